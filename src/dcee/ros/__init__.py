"""dcee as ROS 2 nodes: the search node (:mod:`dcee.ros.node`, ``dcee-ros-node``), the simulated
robot node (:mod:`dcee.ros.sim_node`) and the demo that runs both (:mod:`dcee.ros.demo`,
``dcee-ros-demo``). What they run is ROS-free and lives in :mod:`dcee.robot` (the search
cycle, bags, replay). Importing this package imports no ROS; rclpy is imported only by the node
modules (extra ``ros``: ``bash scripts/setup-ros.sh``)."""
