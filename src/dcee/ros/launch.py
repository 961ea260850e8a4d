"""The ROS 2 entry points (``dcee-ros-node``, ``dcee-ros-demo``): they check that rclpy is
installed before importing anything of ROS, so an environment without it gets one line naming
the setup command and exit 2, not a traceback."""

from __future__ import annotations

import importlib.util

from dcee.console import error_exit

SETUP_HINT = "bash scripts/setup-ros.sh creates .venv-ros with the ROS 2 wheels from PyPI"


def require_rclpy(program: str) -> None:
    """Exit 2 with one line when rclpy (and so the ROS 2 message packages) is not installed."""
    if importlib.util.find_spec("rclpy") is None:
        error_exit(
            program,
            f"rclpy is not installed in this environment; {SETUP_HINT}, then run "
            f".venv-ros/bin/{program}",
        )


def node_main(argv: list[str] | None = None) -> None:
    """``dcee-ros-node``: the search node (:func:`dcee.ros.node.main`)."""
    require_rclpy("dcee-ros-node")
    from dcee.ros.node import main

    main(argv)


def demo_main(argv: list[str] | None = None) -> None:
    """``dcee-ros-demo``: the node against a simulated robot (:func:`dcee.ros.demo.main`)."""
    require_rclpy("dcee-ros-demo")
    from dcee.ros.demo import main

    main(argv)
