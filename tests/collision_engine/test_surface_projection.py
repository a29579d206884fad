"""``surface_projection``: a point's closest surface point and outward normal, on a scene."""
import numpy as np
import pytest

from collision_engine import Box, Pose, Scene, SceneObject, surface_projection

# A 0.1 x 0.2 x 0.06 m box centred 0.075 m below the origin: its faces, written out.
SCENE = Scene([SceneObject('box', Box([0.1, 0.2, 0.06]), Pose(translation=[0.0, 0.0, -0.075]))])
TOP, SIDE = -0.045, 0.05  # [m] z of the top face, x of the +x face


@pytest.mark.parametrize('point, closest, normal', [
    ((0.01, -0.02, 0.0), (0.01, -0.02, TOP), (0.0, 0.0, 1.0)),  # above the top
    ((0.01, 0.03, TOP - 0.002), (0.01, 0.03, TOP), (0.0, 0.0, 1.0)),  # 2 mm inside, under it
    ((0.08, 0.0, -0.07), (SIDE, 0.0, -0.07), (1.0, 0.0, 0.0)),  # beside the +x face
    ((SIDE - 0.001, 0.0, -0.07), (SIDE, 0.0, -0.07), (1.0, 0.0, 0.0)),  # 1 mm inside it
])
def test_the_closest_point_and_normal_are_the_nearest_face_s(point, closest, normal):
    surface, outward = surface_projection(SCENE)(np.array(point))
    np.testing.assert_allclose(surface, closest, atol=1e-12)
    np.testing.assert_allclose(outward, normal, atol=1e-12)
