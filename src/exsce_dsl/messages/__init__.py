"""ROS message definitions: where a type comes from (the bag, rosbags' typestores, the user's
``.msg``/``.idl`` files, in that order) and what fields it has."""
