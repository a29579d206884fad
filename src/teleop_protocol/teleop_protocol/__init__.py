"""What both ends of the teleop link do with what crosses it, so neither site imports the other.

Each end admits the other's messages (``admission``), keeps its half of the passivity books
(``tdpa``) and measures the round trip from echoes (``round_trip``). Plain Python and numpy.
"""
