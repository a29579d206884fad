"""What crosses a topic or a package boundary: the value types, their fields, their checks.

Plain Python and numpy, no rclpy: the producers and the consumers of a message both import it,
so its layout, its codes and the law it carries are written once (``docs/architecture.md``).
"""
