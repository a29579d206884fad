"""The operator site's end of telerobotic ultrasound: the leader between the wand and the link.

Pure Python and numpy below the node (``leader_node``); the ends share ``teleop_protocol``.
"""
