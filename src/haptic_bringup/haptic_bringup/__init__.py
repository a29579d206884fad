"""Bring-up of the haptic loop: launchers, the composed process, recording, the demo."""
