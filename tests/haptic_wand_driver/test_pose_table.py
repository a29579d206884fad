"""Pose tables and their CSV form: round trip, orientation columns, and errors naming the line."""

from ground_truth.wand import quaternion_from_matrix, rotation_x, rotation_z
import numpy as np
import pytest

from haptic_wand_driver.pose_table import PoseFileError, PoseTable, read_pose_csv, write_pose_csv


def test_csv_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(3)
    table = PoseTable(np.cumsum(rng.uniform(1e-4, 1e-2, 50)), rng.normal(size=(50, 5)))
    write_pose_csv(tmp_path / 'poses.csv', table)
    again = read_pose_csv(tmp_path / 'poses.csv')
    np.testing.assert_array_equal(again.times, table.times)
    np.testing.assert_array_equal(again.coordinates, table.coordinates)


def test_quaternion_columns_become_roll_and_yaw(tmp_path):
    qx, qy, qz, qw = map(float, quaternion_from_matrix(rotation_z(-0.3) @ rotation_x(0.25)))
    path = tmp_path / 'q.csv'
    path.write_text(f'qw,t,x,y,z,qx,qy,qz\n{qw!r},0.5,0.1,0.2,0.3,{qx!r},{qy!r},{qz!r}\n')
    table = read_pose_csv(path)
    np.testing.assert_allclose(table.coordinates, [[0.1, 0.2, 0.3, 0.25, -0.3]], atol=1e-12)
    np.testing.assert_array_equal(table.times, [0.5])


def test_missing_orientation_is_zero_and_extra_columns_are_ignored(tmp_path):
    path = tmp_path / 'p.csv'
    path.write_text('t, x, y, z, frame\n0,1,2,3,world\n\n1,4,5,6,world\n')
    table = read_pose_csv(path)
    np.testing.assert_array_equal(table.coordinates, [[1, 2, 3, 0, 0], [4, 5, 6, 0, 0]])


@pytest.mark.parametrize('text, expected', [
    ('', 'empty file'),
    ('t,x,y\n0,0,0\n', r'lacks column\(s\) z'),
    ('t,x,y,z\n', 'header but no poses'),
    ('t,x,y,z,roll\n0,0,0,0,0\n', 'has roll but not all of roll, yaw'),
    ('t,x,y,z,qx,qy,qz\n0,0,0,0,0,0,0\n', 'has qx, qy, qz but not all of qx, qy, qz, qw'),
    ('t,x,y,z,qx,qy,qz,qw,yaw\n0,0,0,0,0,0,0,1,0\n', 'not all of roll, yaw'),
    ('t,x,y,z,roll,yaw,qx,qy,qz,qw\n0,0,0,0,0,0,0,0,0,1\n', 'not both'),
    ('t,x,y,z\n0,0,0,0\n1,0,zero,0\n', 'line 3: could not convert'),
    ('t,x,y,z\n0,0,0,0\n1,0,0\n', 'line 3: 3 fields, header has 4'),
    ('t,x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0.0998,0,0.995\n', 'line 2: .*pitch'),
    ('t,x,y,z\n0,0,0,0\n0,1,1,1\n', 'pose 1 .*does not increase'),
    ('t,x,y,z\n0,0,nan,0\n', 'pose 0 .*finite'),
])
def test_malformed_csv_names_the_file_and_the_problem(tmp_path, text, expected):
    path = tmp_path / 'bad.csv'
    path.write_text(text)
    with pytest.raises(PoseFileError, match=expected) as raised:
        read_pose_csv(path)
    assert str(path) in str(raised.value)


def test_unreadable_files_name_the_file(tmp_path):
    binary = tmp_path / 'binary.csv'
    binary.write_bytes(b'\xff\xfe\x00\x01' * 64)
    for path in (tmp_path / 'missing.csv', binary, tmp_path):
        with pytest.raises(PoseFileError) as raised:
            read_pose_csv(path)
        assert str(path) in str(raised.value)


@pytest.mark.parametrize('times, coordinates', [(np.zeros(0), np.zeros((0, 5))),
                                                (np.zeros(2), np.zeros((2, 5))),
                                                (np.arange(2.0), np.zeros((2, 4)))])
def test_table_refuses_bad_arrays(times, coordinates):
    with pytest.raises(ValueError):
        PoseTable(times, coordinates)
