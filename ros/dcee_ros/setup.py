"""The dcee_ros ROS 2 package (ament_python): installs the search node's executable, its
parameter file and launch description for ``ros2 launch dcee_ros dcee_search.launch.py``.
The node itself is the ``dcee`` Python package (``pip install "dcee[ros]"``)."""

from glob import glob

from setuptools import setup

PACKAGE = "dcee_ros"

setup(
    name=PACKAGE,
    version="0.1.0",
    packages=[],
    data_files=[
        ("share/ament_index/resource_index/packages", [f"resource/{PACKAGE}"]),
        (f"share/{PACKAGE}", ["package.xml"]),
        (f"share/{PACKAGE}/launch", glob("launch/*.launch.py")),
        (f"share/{PACKAGE}/config", glob("config/*.yaml")),
    ],
    install_requires=["setuptools", "dcee[ros]"],
    entry_points={"console_scripts": ["dcee-ros-node = dcee.ros.launch:node_main"]},
)
