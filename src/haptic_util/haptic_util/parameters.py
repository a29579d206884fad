"""Declare a node's ROS parameters from one frozen dataclass: the one place they are listed.

Each field carries its description, unit and valid range (``parameter(...)``). A node reads the
values once into the dataclass and hands that to its pure core, which never sees rclpy. Numbers
are accepted as int or float (YAML writes ``160`` for 160.0, which plain rclpy rejects), and a bad
value stops the node with one line naming the node, the parameter and what is wrong.
"""
import dataclasses
import difflib
import math
import typing
from typing import Any, Optional, Sequence, Type, TypeVar

from rcl_interfaces.msg import ParameterDescriptor
from rclpy.exceptions import ParameterException
from rclpy.node import Node

from haptic_util.executor import StartupError

__all__ = ['parameter', 'declare_parameters', 'RealtimeParams']

T = TypeVar('T')

_KINDS = {bool: 'true or false', str: 'a string', int: 'an integer', float: 'a number',
          tuple: 'a list'}


def parameter(default: Any, description: str, *, unit: str = '', low: Optional[float] = None,
              high: Optional[float] = None, choices: Optional[Sequence[str]] = None,
              length: Optional[int] = None) -> Any:
    """Describe one parameter field of a parameters dataclass.

    ``low``/``high`` bound a number (or every element of a list), inclusive; ``choices`` lists
    the allowed strings; ``length`` fixes the length of a list.
    """
    metadata = dict(description=description, unit=unit, low=low, high=high,
                    choices=tuple(choices) if choices else None, length=length)
    if isinstance(default, (list, tuple)):
        return dataclasses.field(default_factory=lambda: tuple(default), metadata=metadata)
    return dataclasses.field(default=default, metadata=metadata)


@dataclasses.dataclass(frozen=True)
class RealtimeParams:
    """The parameter of the nodes on the 1 kHz path: their process's real-time priority.

    Its process takes the highest its nodes ask for, once they are built
    (``haptic_util.priority.run_realtime``).
    """

    thread_priority: int = parameter(
        0, "SCHED_FIFO priority (1-99) of this node's process, as ros2_control's controller "
        "manager takes for its loop (50); 0 for the system's normal scheduling. Needs root or "
        'an rtprio limit; without either, a warning and normal scheduling', low=0, high=99)


def declare_parameters(node: Node, cls: Type[T]) -> T:
    """Declare every field of ``cls`` on ``node`` and return the validated values."""
    hints = typing.get_type_hints(cls)
    fields = dataclasses.fields(cls)
    _warn_unknown(node, {field.name for field in fields})
    values = {}
    for field in fields:
        default = field.default if field.default is not dataclasses.MISSING \
            else field.default_factory()
        descriptor = _descriptor(field, default)
        try:
            raw = node.declare_parameter(field.name, _as_ros(default), descriptor).value
        except ParameterException:  # rclpy's own type check, e.g. passivity:=1
            raise StartupError(f'{node.get_name()}: parameter {field.name!r} must be '
                               f'{_KINDS[type(default)]}, got '
                               f'{node._parameter_overrides[field.name].value!r}') from None
        values[field.name] = _checked(node.get_name(), field, hints[field.name], raw)
    return cls(**values)


def _warn_unknown(node: Node, fields: set) -> None:
    """Log one line per given parameter this node does not have (a typo is otherwise silent)."""
    for name in sorted(set(node._parameter_overrides) - fields - set(node._parameters)):
        close = difflib.get_close_matches(name, fields, n=1)
        hint = f'; did you mean {close[0]!r}?' if close else ''
        node.get_logger().warn(f'parameter {name!r} is not a parameter of this node, ignored'
                               f'{hint}')


def _descriptor(field: dataclasses.Field, default: Any) -> ParameterDescriptor:
    meta = field.metadata
    text = meta['description'] + (f' [{meta["unit"]}]' if meta['unit'] else '')
    limits = []
    if meta['low'] is not None or meta['high'] is not None:
        limits.append(f'range [{meta["low"]}, {meta["high"]}]')
    if meta['choices']:
        limits.append(f'one of {list(meta["choices"])}')
    if meta['length']:
        limits.append(f'{meta["length"]} elements')
    numeric = isinstance(default, float) or (
        isinstance(default, tuple) and any(isinstance(v, float) for v in default))
    return ParameterDescriptor(name=field.name, description=text,
                               additional_constraints=', '.join(limits),
                               read_only=True, dynamic_typing=numeric)


def _as_ros(default: Any) -> Any:
    return list(default) if isinstance(default, tuple) else default


def _checked(node_name: str, field: dataclasses.Field, hint: Any, raw: Any) -> Any:
    meta = field.metadata

    def fail(problem: str) -> None:
        raise StartupError(f'{node_name}: parameter {field.name!r} {problem}')

    origin = typing.get_origin(hint)
    if origin is tuple:
        element = typing.get_args(hint)[0]
        if not isinstance(raw, (list, tuple)):
            fail(f'must be a list, got {raw!r}')
        value = tuple(_scalar(element, v, fail) for v in raw)
        if meta['length'] and len(value) != meta['length']:
            fail(f'must have {meta["length"]} elements, got {len(value)}')
        for v in value:
            _in_range(v, meta, fail)
        return value
    value = _scalar(hint, raw, fail)
    _in_range(value, meta, fail)
    if meta['choices'] and value not in meta['choices']:
        fail(f'must be one of {list(meta["choices"])}, got {value!r}')
    return value


def _scalar(kind: type, raw: Any, fail) -> Any:
    if kind is float:
        if isinstance(raw, bool) or not isinstance(raw, (int, float)):
            fail(f'must be {_KINDS[float]}, got {raw!r}')
        if not math.isfinite(raw):
            fail(f'must be finite, got {raw!r}')
        return float(raw)
    if (kind is int and isinstance(raw, bool)) or not isinstance(raw, kind):
        fail(f'must be {_KINDS[kind]}, got {raw!r}')
    return raw


def _in_range(value: Any, meta: dict, fail) -> None:
    if isinstance(value, str):
        return
    unit = f' {meta["unit"]}' if meta['unit'] else ''
    if meta['low'] is not None and value < meta['low']:
        fail(f'must be >= {meta["low"]}{unit}, got {value}')
    if meta['high'] is not None and value > meta['high']:
        fail(f'must be <= {meta["high"]}{unit}, got {value}')
