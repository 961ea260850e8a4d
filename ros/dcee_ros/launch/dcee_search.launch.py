"""Launch the dcee search node as a managed (lifecycle) node with its parameter file.

    ros2 launch dcee_ros dcee_search.launch.py params_file:=/path/to/dcee_search.yaml

The node waits unconfigured (``autostart: false`` in the parameter file); bring it up with a
lifecycle manager (Nav2's ``lifecycle_manager`` with ``node_names: [dcee_search]``) or by hand:
``ros2 lifecycle set /dcee_search configure`` then ``activate``, and start a search with
``ros2 service call /dcee/start std_srvs/srv/Trigger``. Requires a ROS 2 installation with
``launch_ros`` (not installable from PyPI) and dcee installed in the same Python
(``pip install "dcee[ros]"``).
"""

from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import LifecycleNode

DEFAULT_PARAMS = str(Path(__file__).resolve().parent.parent / "config" / "dcee_search.yaml")


def generate_launch_description() -> LaunchDescription:
    params_file = LaunchConfiguration("params_file")
    return LaunchDescription(
        [
            DeclareLaunchArgument(
                "params_file",
                default_value=DEFAULT_PARAMS,
                description="the node's parameter file",
            ),
            LifecycleNode(
                package="dcee_ros",
                executable="dcee-ros-node",
                name="dcee_search",
                namespace="",
                output="screen",
                parameters=[params_file],
            ),
        ]
    )
