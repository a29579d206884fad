"""One site of telerobotic ultrasound joined to the other over Zenoh.

A gateway per site carries the crossing topics between the site's DDS domain and one Zenoh
session (mutual TLS, access control by certificate), with the emulated link as a stage before
Zenoh; ``haptic_certs`` makes the sites' CA, keys and certificates.
"""
