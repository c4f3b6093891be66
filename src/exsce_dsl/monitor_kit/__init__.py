"""The monitors' numpy core and runtime: numpy and the standard library only, because
``exscec generate`` copies them into ROS nodes."""
