"""ROS parameters of the bring-up's own nodes: the recorders (their topics: the graph's)."""
from dataclasses import dataclass

from haptic_contract.graph import LOOP_TOPICS
from haptic_util.parameters import parameter, RealtimeParams

__all__ = ['RecorderParams']


@dataclass(frozen=True)
class RecorderParams(RealtimeParams):
    output: str = parameter('bags/haptic_session', 'new bag directory to write')
    topics: tuple[str, ...] = parameter(LOOP_TOPICS, 'topics to record (others than the '
                                        'session\'s are typed from the graph)')
    prefix: str = parameter('', 'put before each topic\'s name in the bag (a site\'s, as '
                            '/remote)')
