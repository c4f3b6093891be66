"""ROS message definitions: where a type comes from (the bag, rosbags' typestores, the user's
``.msg``/``.idl`` files, in that order) and what fields it has; whether the fields a metric reads
are there (:mod:`~exsce_dsl.messages.field_check`)."""
