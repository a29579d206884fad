"""The robot site of telerobotic ultrasound, pure core: robot, sensor, patient, safety, follower.

Pure Python and numpy (trimesh only to make the patient phantom); the ROS nodes come on top of
it.
"""
