"""dcee on a robot: the ROS-free search cycle (:mod:`dcee.ros.cycle`), the ROS 2 node
(:mod:`dcee.ros.node`, ``dcee-ros-node``), the simulated robot node and the demo
(:mod:`dcee.ros.demo`, ``dcee-ros-demo``), bag recording and replay (:mod:`dcee.ros.bag`,
:mod:`dcee.ros.replay`, ``dcee replay``). Importing this package imports no ROS; rclpy is
imported only by the node modules (extra ``ros``: ``bash scripts/setup-ros.sh``)."""
