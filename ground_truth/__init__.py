"""Ground truth for the tests, the benchmarks and the report, sharing no code with the toolkit.

``distances`` (analytic signed distances, brute-force point-triangle distance, winding number),
``wand`` (the wand's analytic rotations, shapes and wall), ``imaging_scenes`` and
``psf_reference`` (imaging scenes, and SIMUS's point-target resolution), ``probe_face`` (a
continuous probe face pressed into a plane, in closed form), ``virtual_wall`` (a device pressed
against a wall, integrated exactly). The references import no toolkit package;
the two harnesses drive one: ``virtual_wall`` hands the force renderer its ``Contact``, and
``psf_reference`` images with the model it measures against SIMUS (``tests/test_ground_truth.py``).
"""
