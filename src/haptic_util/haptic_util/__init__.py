"""Shared rclpy plumbing of the haptic nodes: QoS, executor and start-up, stamps."""
