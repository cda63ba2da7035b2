"""The sweep tasks, one module per family, each calling the existing library.

``fk`` (``fk_stability_map``), ``plan`` (``plan_suite``, ``plan_robustness``) and ``cdpr``
(``cdpr_workspace``, ``cdpr_deployment``) each define :class:`taut.sweep.Task` values;
:data:`taut.sweep.TASKS` collects them by name.
"""
