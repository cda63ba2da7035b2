"""The robot doing its job (issue 30): the warehouse it works in, navigation of the coupled bases, where to stand for each group of tasks, and the mission built on them."""
