"""Declarations of scenario_execution's ``osc.ros`` and ``osc.nav2`` libraries, without ROS.

scenario_execution's parser resolves ``import osc.<name>`` through the entry point group
``scenario_execution.osc_libraries`` and, even with ``-n`` (dry run), builds the behaviour tree:
every action invoked must have a plug-in in ``scenario_execution.actions`` whose ``__init__`` and
``execute`` take the arguments the ``.osc`` declaration names.  The real plug-ins come with ROS
(``scenario_execution_ros``, ``scenario_execution_nav2``); these stand-ins only declare them, so
that an exported scenario can be parsed and resolved on a machine without ROS.  They never run.
"""
