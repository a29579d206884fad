"""The robot site of telerobotic ultrasound, pure core: robot, sensor, patient, safety, follower.

Pure Python and numpy (trimesh only to make the patient phantom); ``assembly`` builds the parts
from their parameters, and the ROS nodes come on top of it.
"""
