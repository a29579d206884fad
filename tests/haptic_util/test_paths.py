"""package:// URIs stay inside their package's share folder; anything else is a clear error."""

import pytest

from haptic_util.executor import StartupError
from haptic_util.paths import resolve_path


@pytest.fixture
def prefix(tmp_path, monkeypatch):
    """An ament prefix holding package 'fake' (share/fake/scenes/a.yaml) and a file beside it."""
    root = tmp_path / 'install'
    (root / 'share' / 'ament_index' / 'resource_index' / 'packages').mkdir(parents=True)
    (root / 'share' / 'ament_index' / 'resource_index' / 'packages' / 'fake').touch()
    (root / 'share' / 'fake' / 'scenes').mkdir(parents=True)
    (root / 'share' / 'fake' / 'scenes' / 'a.yaml').write_text('objects: []\n')
    (tmp_path / 'outside').mkdir()
    (tmp_path / 'outside' / 'secret.yaml').write_text('objects: []\n')
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(root))
    return root


def error(value: str) -> str:
    with pytest.raises(StartupError) as raised:
        resolve_path(value, what='parameter scene_file')
    message = str(raised.value)
    assert 'parameter scene_file' in message and repr(value) in message
    return message


def test_a_file_in_the_share_folder(prefix):
    share = prefix / 'share' / 'fake'
    assert resolve_path('package://fake/scenes/a.yaml', what='x') == share / 'scenes' / 'a.yaml'
    # '..' that stays inside is normalised, not refused.
    assert resolve_path('package://fake/scenes/../scenes/./a.yaml', what='x') == \
        share / 'scenes' / 'a.yaml'


@pytest.mark.parametrize('value', ['package://fake//etc/passwd', 'package://fake///etc/passwd'])
def test_an_absolute_path_after_the_package_is_refused(prefix, value):
    assert 'must be relative' in error(value)


@pytest.mark.parametrize('value', ['package://fake/../../outside/secret.yaml',
                                   'package://fake/scenes/../../../outside/secret.yaml',
                                   'package://fake/..', 'package://fake', 'package://fake/',
                                   'package://fake/scenes/..'])
def test_dot_dot_out_of_the_share_folder_or_no_file_is_refused(prefix, value):
    assert 'names no file inside the share folder' in error(value)


def test_a_symlink_out_of_the_share_folder_is_refused(prefix, tmp_path):
    share = prefix / 'share' / 'fake'
    (share / 'scenes' / 'linked.yaml').symlink_to(tmp_path / 'outside' / 'secret.yaml')
    (share / 'elsewhere').symlink_to(tmp_path / 'outside', target_is_directory=True)
    for value in ('package://fake/scenes/linked.yaml', 'package://fake/elsewhere/secret.yaml'):
        assert 'through a symbolic link' in error(value)


def test_a_symlink_within_the_share_folder_is_followed(prefix):
    share = prefix / 'share' / 'fake'
    (share / 'b.yaml').symlink_to(share / 'scenes' / 'a.yaml')
    assert resolve_path('package://fake/b.yaml', what='x').read_text() == 'objects: []\n'


def test_unknown_package_and_missing_file(prefix):
    assert "package 'nothing' is not installed" in error('package://nothing/a.yaml')
    assert 'no such file' in error('package://fake/scenes/missing.yaml')


def test_plain_paths_are_unchanged(tmp_path):
    path = tmp_path / 'outside.yaml'
    path.write_text('objects: []\n')
    assert resolve_path(str(path), what='x') == path
    assert 'is empty' in str(pytest.raises(StartupError, resolve_path, '', what='x').value)
