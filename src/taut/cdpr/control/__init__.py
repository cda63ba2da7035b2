"""Control of the moving cable robot (FASTKIT paper 2.2, 3.1): dynamics parameters, model errors, references, controllers, the simulated plant and the simulation."""
