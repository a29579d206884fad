"""The scene file: parse and validate a YAML scene without building any geometry.

Reading a scene imports neither trimesh nor fcl and loads no mesh, so a tool (or the node's
parameter check) can reject a bad file in milliseconds. Every mistake raises a ``SceneError``
with one line naming the file, by the path as it was given, and the key path, e.g.
``scenes/cuboid.yaml: objects[0].material.stiffness: must be 3 finite numbers >= 0, got [160,
nan]``.

Format (SI units, REP-103 frames; paths relative to the scene file)::

    frame_id: world                 # optional, default world
    tip_radius: 0.0                 # optional, m: the wand tip is a sphere of this radius
    tool:                           # optional: the probe, a convex shape (not with tip_radius)
      shape: {box: {size: [0.01, 0.04, 0.06]}}
      offset: {position: [0.0, 0.0, 0.03], rpy: [0.0, 0.0, 0.0]}   # tool frame in the tip frame
      face_spacing: 0.005           # optional, m: the contact face's point grid (``tool``)
    cross_validation: {fcl: true, every: 10, tolerance: 1.0e-6}   # optional, default off
    objects:
      - name: cuboid                # unique
        shape: {box: {size: [0.1, 0.1, 0.2]}}
        pose: {position: [0.0, 0.0, -0.075], rpy: [0.0, 0.0, 0.0]}   # or quaternion: [x, y, z, w]
        material: {stiffness: [160, 160, 160], damping: [0.8, 0.8, 0.8]}   # optional
    anatomy:                        # optional: what the ultrasound image sees, never the force
      media:                        # acoustic properties, by tissue name
        liver: {speed_of_sound: 1595.0, impedance: 1.65e6, attenuation: 0.5,
                scatterer_density: 50.0, scatterer_amplitude: 0.004}
        fluid: {speed_of_sound: 1480.0, impedance: 1.48e6, attenuation: 0.002,
                scatterer_density: 0.0, scatterer_amplitude: 0.0}
      structures:                   # painted in order: where they overlap, the later one wins
        - {name: body, object: cuboid, medium: liver}   # an object's own surface and pose
        - name: cyst                # or a shape and pose of its own, as objects have
          shape: {sphere: {radius: 0.01}}
          pose: {position: [0.0, 0.0, -0.05]}
          medium: fluid

Shapes: ``box: {size}``, ``sphere: {radius}``, ``cylinder: {radius, height}`` (axis z),
``capsule: {radius, length}`` (axis z, ``length`` of the segment), ``mesh: {file, scale,
convex}`` (``file`` relative to the scene file's folder, absolute, ``~/...`` or
``package://<pkg>/<path>``; ``scale`` from file units to m, default 1; ``convex`` true queries
the mesh's convex hull by GJK, false the exact non-convex surface; omitted, it is detected on
load).

Anatomy media: ``speed_of_sound`` m/s, ``impedance`` kg/(m^2 s) (Rayl), ``attenuation``
dB/(cm MHz), ``scatterer_density`` per mm^3 and ``scatterer_amplitude`` (one scatterer's echo
over a perfect plane reflector's), all five required. The anatomy is parsed here, strictly, and
built by the ultrasound simulator alone: ``load_scene`` makes no collision object of it, so a
scene's forces and distances are the same with or without it.

The tool takes the same shapes but a mesh must be convex (``convex: false`` is refused here, a
non-convex file when the scene is loaded, naming the file). Without a ``tool`` the tip is a point
(or a sphere of ``tip_radius``). Its size against the workspace is checked on load, where the
workspace is known.
"""

from dataclasses import dataclass
import difflib
import math
from pathlib import Path

import numpy as np
import yaml

from collision_engine.errors import SceneError
from collision_engine.transforms import Pose
from haptic_contract.checks import whole_number

__all__ = ['AnatomySpec', 'BoxSpec', 'CapsuleSpec', 'CrossValidationSpec', 'CylinderSpec',
           'MaterialSpec', 'MediumSpec', 'MeshSpec', 'ObjectSpec', 'SceneSpec', 'SphereSpec',
           'StructureSpec', 'ToolSpec', 'read_scene']


@dataclass(frozen=True)
class BoxSpec:
    """``size``: full edge lengths (3,), m."""

    size: tuple[float, float, float]


@dataclass(frozen=True)
class SphereSpec:
    """``radius``, m."""

    radius: float


@dataclass(frozen=True)
class CylinderSpec:
    """``radius`` and full ``height``, m; axis z."""

    radius: float
    height: float


@dataclass(frozen=True)
class CapsuleSpec:
    """``radius`` and segment ``length``, m; axis z."""

    radius: float
    length: float


@dataclass(frozen=True)
class MeshSpec:
    """A mesh file (absolute path), its unit ``scale`` to m, and ``convex`` (None: detect)."""

    file: Path
    scale: float
    convex: bool | None


@dataclass(frozen=True, eq=False)
class MaterialSpec:
    """Per-axis spring-damper gains: ``stiffness`` (3,) N/m, ``damping`` (3,) N s/m."""

    stiffness: np.ndarray
    damping: np.ndarray


@dataclass(frozen=True)
class CrossValidationSpec:
    """FCL cross-check of every ``every``-th query, ``tolerance`` m beyond FCL's own error."""

    fcl: bool = False
    every: int = 1
    tolerance: float = 1e-6


@dataclass(frozen=True, eq=False)
class ObjectSpec:
    """One scene object: ``name``, ``shape`` (a *Spec), ``pose`` (Pose), ``material``."""

    name: str
    shape: BoxSpec | SphereSpec | CylinderSpec | CapsuleSpec | MeshSpec
    pose: Pose
    material: MaterialSpec | None


@dataclass(frozen=True, eq=False)
class ToolSpec:
    """The probe: ``shape`` (a *Spec), ``offset`` (its frame in the tip's), ``face_spacing`` m."""

    shape: BoxSpec | SphereSpec | CylinderSpec | CapsuleSpec | MeshSpec
    offset: Pose
    face_spacing: float


@dataclass(frozen=True)
class MediumSpec:
    """A tissue's acoustic properties (units in the module docstring)."""

    speed_of_sound: float
    impedance: float
    attenuation: float
    scatterer_density: float
    scatterer_amplitude: float


@dataclass(frozen=True, eq=False)
class StructureSpec:
    """One anatomical structure: ``shape`` at ``pose``, filled with the medium named ``medium``.

    ``object`` names the scene object whose shape and pose it shares (None: its own).
    """

    name: str
    shape: BoxSpec | SphereSpec | CylinderSpec | CapsuleSpec | MeshSpec
    pose: Pose
    medium: str
    object: str | None = None


@dataclass(frozen=True, eq=False)
class AnatomySpec:
    """What the ultrasound image sees: ``media`` by name, ``structures`` in painting order."""

    media: dict[str, MediumSpec]
    structures: tuple[StructureSpec, ...]


@dataclass(frozen=True, eq=False)
class SceneSpec:
    """A validated scene file: ``path``, ``frame_id``, ``tip_radius`` m, objects, ``tool``.

    ``anatomy`` is None for a scene without acoustic properties.
    """

    path: Path
    frame_id: str
    tip_radius: float
    cross_validation: CrossValidationSpec
    objects: tuple[ObjectSpec, ...]
    tool: ToolSpec | None = None
    anatomy: AnatomySpec | None = None


DEFAULT_FACE_SPACING = 0.005  # m: a 10 x 40 mm probe face gets 2 x 8 points

_MEDIUM_KEYS = ('speed_of_sound', 'impedance', 'attenuation', 'scatterer_density',
                'scatterer_amplitude')
_POSITIVE_MEDIUM_KEYS = ('speed_of_sound', 'impedance')

_SHAPE_KEYS = {
    'box': (('size',), ()),
    'sphere': (('radius',), ()),
    'cylinder': (('radius', 'height'), ()),
    'capsule': (('radius', 'length'), ()),
    'mesh': (('file',), ('scale', 'convex')),
}


class _Reader:
    """Typed access to the parsed YAML, failing with the file name and the key path."""

    def __init__(self, path: Path) -> None:
        self.path = path

    def fail(self, where: str, message: str):
        raise SceneError(f'{self.path}: {where}: {message}')

    def mapping(self, value, where: str, required=(), optional=()) -> dict:
        if not isinstance(value, dict):
            self.fail(where, f'must be a mapping, got {type(value).__name__} {value!r}')
        allowed = (*required, *optional)
        for key in value:
            if key not in allowed:
                close = difflib.get_close_matches(str(key), allowed, n=1)
                hint = f' (did you mean {close[0]!r}?)' if close else ''
                self.fail(_join(where, key), f'unknown key{hint}; allowed: {", ".join(allowed)}')
        for key in required:
            if key not in value:
                self.fail(_join(where, key), 'missing')
        return value

    def number(self, value, where: str, *, minimum: float = -math.inf,
               strict: bool = False) -> float:
        relation = '>' if strict else '>='
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(where, f'must be a number, got {type(value).__name__} {value!r}')
        number = float(value)
        if not math.isfinite(number) or number < minimum or (strict and number == minimum):
            bound = '' if minimum == -math.inf else f' {relation} {minimum:g}'
            self.fail(where, f'must be a finite number{bound}, got {value!r}')
        return number

    def count(self, value, where: str) -> int:
        return whole_number(value, f'{self.path}: {where}:', error=SceneError)

    def vector(self, value, where: str, length: int, *, minimum: float = -math.inf,
               strict: bool = False) -> np.ndarray:
        if not isinstance(value, list) or len(value) != length:
            self.fail(where, f'must be a list of {length} numbers, got {value!r}')
        try:
            numbers = [self.number(v, where, minimum=minimum, strict=strict) for v in value]
        except SceneError:
            relation = '>' if strict else '>='
            bound = '' if minimum == -math.inf else f' {relation} {minimum:g}'
            self.fail(where, f'must be {length} finite numbers{bound}, got {value!r}')
        return np.array(numbers)

    def boolean(self, value, where: str) -> bool:
        if not isinstance(value, bool):
            self.fail(where, f'must be true or false, got {value!r}')
        return value

    def text(self, value, where: str) -> str:
        if not isinstance(value, str) or not value:
            self.fail(where, f'must be a non-empty string, got {value!r}')
        return value


def _join(where: str, key) -> str:
    return f'{where}.{key}' if where else str(key)


def read_scene(path) -> SceneSpec:
    """Parse and validate a scene file; build no geometry and load no mesh.

    Parameters
    ----------
    path : str or pathlib.Path
        The YAML scene. Mesh files are resolved relative to its folder and must exist.

    Returns
    -------
    SceneSpec

    Raises
    ------
    SceneError
        On a missing or unparsable file, an unknown or missing key, a wrong type, a NaN,
        negative or zero value where a positive one is needed, an unknown shape, a duplicate
        object name or a missing mesh file; the message names the file and the key path.
    """
    path = Path(path)
    reader = _Reader(path)
    try:
        document = yaml.safe_load(path.read_text(encoding='utf-8'))
    except OSError as error:
        raise SceneError(f'{path}: cannot read the scene file: {error.strerror}') from None
    except UnicodeDecodeError as error:
        raise SceneError(f'{path}: not a text file (byte {error.start} is not UTF-8)') from None
    except yaml.YAMLError as error:
        mark = getattr(error, 'problem_mark', None)
        at = f'line {mark.line + 1}' if mark is not None else 'document'
        raise SceneError(f'{path}: {at}: not valid YAML: '
                         f'{getattr(error, "problem", error)}') from None
    top = reader.mapping(document, '', ('objects',),
                         ('frame_id', 'tip_radius', 'cross_validation', 'tool', 'anatomy'))
    frame_id = reader.text(top.get('frame_id', 'world'), 'frame_id')
    tip_radius = reader.number(top.get('tip_radius', 0.0), 'tip_radius', minimum=0.0)
    cross_validation = _cross_validation(reader, top.get('cross_validation', {}))
    if not isinstance(top['objects'], list):
        reader.fail('objects', f'must be a list, got {top["objects"]!r}')
    objects = tuple(_object(reader, item, f'objects[{i}]')
                    for i, item in enumerate(top['objects']))
    names = [o.name for o in objects]
    for i, name in enumerate(names):
        if name in names[:i]:
            reader.fail(f'objects[{i}].name', f'duplicate name {name!r}')
    tool = None
    if top.get('tool') is not None:
        if tip_radius > 0.0:
            reader.fail('tool', 'give tool or tip_radius, not both (the tool is the tip)')
        tool = _tool(reader, top['tool'])
    anatomy = None
    if top.get('anatomy') is not None:
        anatomy = _anatomy(reader, top['anatomy'], {o.name: o for o in objects})
    return SceneSpec(path, frame_id, tip_radius, cross_validation, objects, tool, anatomy)


def _anatomy(reader: _Reader, value, objects: dict) -> AnatomySpec:
    fields = reader.mapping(value, 'anatomy', ('media', 'structures'))
    media = fields['media']
    if not isinstance(media, dict) or not media:
        reader.fail('anatomy.media', f'must be a mapping of at least one medium, got {media!r}')
    media = {reader.text(name, f'anatomy.media.{name}'): _medium(reader, properties,
                                                                 f'anatomy.media.{name}')
             for name, properties in media.items()}
    listed = fields['structures']
    if not isinstance(listed, list) or not listed:
        reader.fail('anatomy.structures', f'must be a non-empty list, got {listed!r}')
    structures = []
    for i, item in enumerate(listed):
        where = f'anatomy.structures[{i}]'
        structure = _structure(reader, item, where, media, objects)
        if structure.name in [s.name for s in structures]:
            reader.fail(f'{where}.name', f'duplicate name {structure.name!r}')
        structures.append(structure)
    return AnatomySpec(media, tuple(structures))


def _medium(reader: _Reader, value, where: str) -> MediumSpec:
    fields = reader.mapping(value, where, _MEDIUM_KEYS)
    return MediumSpec(*(reader.number(fields[key], f'{where}.{key}', minimum=0.0,
                                      strict=key in _POSITIVE_MEDIUM_KEYS)
                        for key in _MEDIUM_KEYS))


def _structure(reader: _Reader, value, where: str, media: dict, objects: dict) -> StructureSpec:
    fields = reader.mapping(value, where, ('name', 'medium'), ('object', 'shape', 'pose'))
    name = reader.text(fields['name'], f'{where}.name')
    medium = reader.text(fields['medium'], f'{where}.medium')
    if medium not in media:
        reader.fail(f'{where}.medium', f'no medium {medium!r} in anatomy.media '
                    f'({", ".join(media)})')
    if ('object' in fields) == ('shape' in fields):
        reader.fail(where, 'give object (an object\'s own surface) or shape, one of them')
    if 'shape' in fields:
        return StructureSpec(name, _shape(reader, fields['shape'], f'{where}.shape'),
                             _pose(reader, fields.get('pose', {}), f'{where}.pose'), medium)
    if 'pose' in fields:
        reader.fail(f'{where}.pose', 'an object\'s surface has the object\'s pose')
    shared = reader.text(fields['object'], f'{where}.object')
    if shared not in objects:
        reader.fail(f'{where}.object', f'no object {shared!r} in objects')
    return StructureSpec(name, objects[shared].shape, objects[shared].pose, medium, shared)


def _tool(reader: _Reader, value) -> ToolSpec:
    fields = reader.mapping(value, 'tool', ('shape',), ('offset', 'face_spacing'))
    shape = _shape(reader, fields['shape'], 'tool.shape')
    if isinstance(shape, MeshSpec) and shape.convex is False:
        reader.fail('tool.shape.mesh.convex', 'must be true or omitted: a tool is convex')
    offset = _pose(reader, fields.get('offset', {}), 'tool.offset')
    spacing = reader.number(fields.get('face_spacing', DEFAULT_FACE_SPACING),
                            'tool.face_spacing', minimum=0.0, strict=True)
    return ToolSpec(shape, offset, spacing)


def _cross_validation(reader: _Reader, value) -> CrossValidationSpec:
    where = 'cross_validation'
    fields = reader.mapping(value, where, (), ('fcl', 'every', 'tolerance'))
    return CrossValidationSpec(
        fcl=reader.boolean(fields.get('fcl', False), f'{where}.fcl'),
        every=reader.count(fields.get('every', 1), f'{where}.every'),
        tolerance=reader.number(fields.get('tolerance', 1e-6), f'{where}.tolerance',
                                minimum=0.0, strict=True))


def _object(reader: _Reader, value, where: str) -> ObjectSpec:
    fields = reader.mapping(value, where, ('name', 'shape'), ('pose', 'material'))
    name = reader.text(fields['name'], f'{where}.name')
    shape = _shape(reader, fields['shape'], f'{where}.shape')
    pose = _pose(reader, fields.get('pose', {}), f'{where}.pose')
    material = None
    if fields.get('material') is not None:
        material = _material(reader, fields['material'], f'{where}.material')
    return ObjectSpec(name, shape, pose, material)


def _shape(reader: _Reader, value, where: str):
    fields = reader.mapping(value, where, (), tuple(_SHAPE_KEYS))
    if len(fields) != 1:
        reader.fail(where, f'must name exactly one shape of {", ".join(_SHAPE_KEYS)}, '
                    f'got {list(fields) or "none"}')
    (kind, params), = fields.items()
    where = f'{where}.{kind}'
    params = reader.mapping(params, where, *_SHAPE_KEYS[kind])

    def length(key):
        return reader.number(params[key], f'{where}.{key}', minimum=0.0, strict=True)

    if kind == 'box':
        size = reader.vector(params['size'], f'{where}.size', 3, minimum=0.0, strict=True)
        return BoxSpec(tuple(size.tolist()))
    if kind == 'sphere':
        return SphereSpec(length('radius'))
    if kind == 'cylinder':
        return CylinderSpec(length('radius'), length('height'))
    if kind == 'capsule':
        return CapsuleSpec(length('radius'), length('length'))
    file = _mesh_file(reader, reader.text(params['file'], f'{where}.file'), f'{where}.file')
    scale = reader.number(params.get('scale', 1.0), f'{where}.scale', minimum=0.0, strict=True)
    convex = params.get('convex')
    if convex is not None:
        convex = reader.boolean(convex, f'{where}.convex')
    return MeshSpec(file.resolve(), scale, convex)


def _mesh_file(reader: _Reader, given: str, where: str) -> Path:
    """Find an existing mesh file as the scene gives it.

    Relative to the scene file's folder (``a.stl``, ``./a.stl``, ``../meshes/a.stl``), whatever
    the working directory; absolute; under the user's home (``~/a.stl``); or
    ``package://<pkg>/<path>`` inside a package's share folder (``haptic_util.paths``).
    """
    if given.startswith('package://'):
        from haptic_util.paths import package_file

        try:
            file = package_file(given)
        except ValueError as error:
            reader.fail(where, str(error))
    else:
        try:
            file = reader.path.parent / Path(given).expanduser()  # absolute replaces the base
        except RuntimeError as error:  # ~user for an unknown user
            reader.fail(where, f'cannot expand {given!r}: {error}')
    if not file.is_file():
        reader.fail(where, f'no such file: {file}')
    return file


def _pose(reader: _Reader, value, where: str) -> Pose:
    fields = reader.mapping(value, where, (), ('position', 'rpy', 'quaternion'))
    if 'rpy' in fields and 'quaternion' in fields:
        reader.fail(where, 'give rpy or quaternion, not both')
    position = reader.vector(fields.get('position', [0.0, 0.0, 0.0]), f'{where}.position', 3)
    if 'quaternion' in fields:
        quaternion = reader.vector(fields['quaternion'], f'{where}.quaternion', 4)
        if np.linalg.norm(quaternion) < 1e-9:
            reader.fail(f'{where}.quaternion', f'must be non-zero, got {fields["quaternion"]}')
        return Pose.from_quaternion(position, quaternion)
    rpy = reader.vector(fields.get('rpy', [0.0, 0.0, 0.0]), f'{where}.rpy', 3)
    return Pose.from_rpy(position, rpy)


def _material(reader: _Reader, value, where: str) -> MaterialSpec:
    fields = reader.mapping(value, where, ('stiffness', 'damping'))
    stiffness = reader.vector(fields['stiffness'], f'{where}.stiffness', 3, minimum=0.0)
    damping = reader.vector(fields['damping'], f'{where}.damping', 3, minimum=0.0)
    stiffness.setflags(write=False)
    damping.setflags(write=False)
    return MaterialSpec(stiffness, damping)
