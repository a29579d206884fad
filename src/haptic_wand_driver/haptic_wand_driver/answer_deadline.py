"""When an answer stops being rendered: at its lifetime, or later while the next pose is late.

Why: an answer (a wrench, or a contact model) holds for its lifetime after the pose it answers
(``wrench_timeout``, a model's ``valid_for``), so a loop that stops answering leaves no force
behind. But a driver that is late to send its next pose has no newer answer to give. On a busy
machine the tick stretches, the answer expires inside it, the force drops to zero, the hand
pushes the wand in, and the next answer meets it deeper and throws it back out (the telerobotic
scan with one core hogged: net work on the hand +17 and +21 mJ, 11-12 % oscillation, replayed in
lockstep from the ticks two loaded runs recorded). With ``hold`` longer than the lifetime, the
answer to the newest pose sent holds until the next pose is sent, at most ``hold`` after its pose;
once a newer pose is out, it expires at its lifetime or at that pose's sending, whichever is later.
A loop that stops answering while the driver ticks still zeroes the force at the lifetime.

Times are the stamps' clock (ROS time), s.
"""
import math

__all__ = ['AnswerDeadline']


class AnswerDeadline:
    """The deadline of the answer held, from the poses sent and the answers taken.

    Parameters
    ----------
    hold : float, s
        The longest an answer to the newest pose holds after its pose while the next is late;
        at most its lifetime (0, say) keeps each answer to its lifetime.
    """

    def __init__(self, hold: float) -> None:
        self.hold = hold
        self.late = 0  # poses sent after the held answer's lifetime had run out
        self._newest = -math.inf  # the newest pose sent
        self._held = (-math.inf, 0.0)  # the held answer's pose and lifetime
        self._next = -math.inf  # when the first pose after the held answer's went out

    def sent(self, stamp: float, at: float) -> bool:
        """Book the pose stamped ``stamp`` as sent at ``at``; return whether the deadline moved.

        Call it once the pose is out (and, in one process, answered): a tick can stall between
        its stamp and its sending, and the answer held must cover that too.
        """
        answered, lifetime = self._held
        first = self._next == math.inf and stamp > answered
        if first:
            self._next = at
            self.late += at > answered + lifetime
        self._newest = stamp
        return first and self.hold > lifetime

    def taken(self, stamp: float, lifetime: float) -> None:
        """Hold the answer to the pose stamped ``stamp``, alive ``lifetime`` after it."""
        self._held = (stamp, lifetime)
        # The first pose after an older one went out at an instant not kept: its lifetime only.
        self._next = math.inf if stamp >= self._newest else -math.inf

    @property
    def deadline(self) -> float:
        """When the held answer stops being rendered (-inf when none was taken)."""
        answered, lifetime = self._held
        if self.hold <= lifetime:
            return answered + lifetime
        return min(max(answered + lifetime, self._next), answered + self.hold)
