"""Where ``import osc.ros`` and ``import osc.nav2`` find their declarations: the package and the
file under its ``lib_osc`` folder, as scenario_execution's own libraries answer."""


def ros_library() -> tuple[str, str]:
    return "exsce_osc2_declarations", "ros.osc"


def nav2_library() -> tuple[str, str]:
    return "exsce_osc2_declarations", "nav2.osc"
