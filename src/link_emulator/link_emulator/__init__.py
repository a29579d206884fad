"""The emulated link between the two sites, apart from both: delay, jitter, loss, a trace.

Pure below ``link_stage``, the one module that holds a node's messages for the link.
"""
