"""The ROS parameters of the emulated link, a stage of the site gateway."""
from dataclasses import dataclass

from haptic_util.parameters import parameter

__all__ = ['LinkStageParams']


@dataclass(frozen=True)
class LinkStageParams:
    """The emulated link's parameters (the site gateway's outgoing stage)."""

    delay: float = parameter(0.0, 'one-way delay of the emulated link', unit='s', low=0.0,
                             high=10.0)
    jitter: float = parameter(0.0, 'standard deviation of the Gaussian jitter added to each '
                              "message's delay", unit='s', low=0.0, high=10.0)
    loss: float = parameter(0.0, 'probability that a message is lost', low=0.0, high=0.99)
    reorder: bool = parameter(False, 'a message may overtake an earlier one (else a late one '
                              'holds back those behind it)')
    seed: int = parameter(0, 'seed of the draws: to_remote uses it, to_operator seed + 1',
                          low=0)
    delay_trace: str = parameter('', 'CSV of one-way delays (header time,delay, in s) replayed '
                                 'from each direction\'s first message, instead of delay; '
                                 'empty: none')
