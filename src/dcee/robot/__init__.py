"""dcee on a robot, without ROS: the search cycle a robot runs (:mod:`~dcee.robot.cycle`: settle,
average, assimilate, decide), a simulated unicycle robot in continuous time
(:mod:`~dcee.robot.simulated`), ROS 2 bags read and written with ``rosbags``
(:mod:`~dcee.robot.bag`) and the replay of a recorded search (:mod:`~dcee.robot.replay`,
``dcee replay``). The ROS 2 node (:mod:`dcee.ros`) and the command line both use it; it
imports no ROS."""
