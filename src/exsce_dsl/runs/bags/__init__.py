"""Step 1 of a run: reading bags (ROS 1, MCAP, rosbags' readers) into numpy columns over raw bytes."""
