"""One scene serves both: the anatomy changes no force or distance, and is what the image sees."""

from ground_truth.distances import scene_path
import numpy as np
import trimesh

from collision_engine import load_scene, read_scene
from collision_engine.probe import query_probe
from ultrasound_sim import load_anatomy
from ultrasound_sim.phantom_anatomy import anatomy_meshes, DEFAULT_FOLDER, main


def test_the_anatomy_changes_no_distance_the_collision_engine_computes():
    with_anatomy = load_scene(scene_path('phantom_anatomy'))
    without = load_scene(scene_path('probe_phantom'))
    assert with_anatomy.names == without.names == ('patient',)
    rng = np.random.default_rng(29)
    points = rng.uniform([-0.05, -0.05, -0.08], [0.05, 0.05, 0.0], (200, 3))
    np.testing.assert_array_equal(with_anatomy.query_rows(points), without.query_rows(points))
    for _ in range(20):  # the probe's whole contact: tool and face, pressed or lifted
        position = rng.uniform([-0.02, -0.02, -0.04], [0.02, 0.02, -0.02])
        quaternion = rng.normal(size=4)
        quaternion /= np.linalg.norm(quaternion)
        a = query_probe(with_anatomy, position, quaternion)
        b = query_probe(without, position, quaternion)
        np.testing.assert_array_equal(a.distance, b.distance)
        np.testing.assert_array_equal(a.normals, b.normals)
        assert a.tool.distance == b.tool.distance


def test_the_phantom_anatomy_is_closed_and_in_order():
    anatomy = load_anatomy(scene_path('phantom_anatomy'))
    assert anatomy.names == ('skin', 'fat', 'muscle', 'abdomen', 'organ', 'vessel', 'cyst',
                             'rib')
    for index, name in enumerate(anatomy.names):
        faces = anatomy.triangles[anatomy.owner == index]
        mesh = trimesh.Trimesh(anatomy.vertices, faces, process=True)
        assert mesh.is_watertight, name  # closed: the scan plane cuts it into closed outlines
        assert mesh.volume > 0.0, name
    spec = read_scene(scene_path('phantom_anatomy'))
    assert spec.anatomy.structures[0].object == 'patient'
    assert spec.anatomy.structures[0].shape == spec.objects[0].shape


def test_the_shipped_meshes_are_the_ones_the_script_makes(tmp_path):
    main([str(tmp_path)])
    for stem in anatomy_meshes():
        assert (tmp_path / f'{stem}.stl').read_bytes() == \
            (DEFAULT_FOLDER / f'{stem}.stl').read_bytes(), stem
