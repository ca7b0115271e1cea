"""comanip in a ROS 2 robot's loop: a node that estimates the goal of the hand's reach as its pose and twist
arrive, and publishes the estimate, the predicted hand path and the handover's impedance schedule
(:mod:`comanip.ros.node`); a replay of recorded hand states through it (:mod:`comanip.ros.replay`).

Needs the optional extra: ``pip install -e ".[ros]"`` (ROS 2's rclpy and message packages as wheels; no ROS
installation). :mod:`comanip.ros.node_settings` needs neither.
"""
