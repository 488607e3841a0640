"""The line protocol of the arm controller and the DAQ (docs/protocol.md): framing only, no transport.

A request is one ASCII line ``<seq> <COMMAND> [args...]\\n``; a reply is
``<seq> OK [values...] *<cc>\\n``, ``<seq> DATA [values...] *<cc>\\n`` (streamed
samples) or ``<seq> ERR <CODE> <message> *<cc>\\n``, where ``seq`` is the
request's sequence number (0–65535) and ``cc`` two hex digits: the XOR of
every byte before the ``*``. Numbers are decimal; angles in degrees.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..rig import ProtocolError, RigError

__all__ = [
    "Reply",
    "encode_request",
    "encode_reply",
    "parse_reply",
    "parse_request",
    "checksum",
    "ARM_COMMANDS",
    "DAQ_COMMANDS",
    "MAX_LINE",
]

#: Commands of each device and their argument counts.
ARM_COMMANDS = {"MOVE": 3, "POSE": 0, "STOP": 0, "STATUS": 0, "SERVO": 4, "AXLE": 0}
DAQ_COMMANDS = {"READ": 1, "STREAM": 1, "ZERO": 0, "STATUS": 0}
#: Longest line either side sends, bytes (a longer one is garbage).
MAX_LINE = 256


def checksum(body: bytes) -> str:
    """Two hex digits: the XOR of the bytes of ``body``."""
    c = 0
    for b in body:
        c ^= b
    return f"{c:02X}"


def _number(x: float) -> str:
    x = float(x)
    if not math.isfinite(x):
        raise RigError(f"cannot send {x!r}: values on the wire must be finite")
    return repr(x)


def encode_request(seq: int, command: str, *args: float) -> bytes:
    """``<seq> <COMMAND> [args...]\\n`` (numbers written exactly, as Python's repr).

    Examples
    --------
    >>> encode_request(3, "MOVE", 10.0, -2.5, 30.0)
    b'3 MOVE 10.0 -2.5 30.0\\n'
    >>> parse_request(b'3 MOVE 10.0 -2.5 30.0', ARM_COMMANDS)
    (3, 'MOVE', [10.0, -2.5, 30.0])
    """
    parts = [str(int(seq) % 65536), command] + [_number(a) if not isinstance(a, int) else str(a) for a in args]
    return (" ".join(parts) + "\n").encode("ascii")


def encode_reply(seq: int, status: str, *fields: str | float) -> bytes:
    """``<seq> <OK|DATA|ERR> [fields...] *<cc>\\n``; float fields written exactly.

    Examples
    --------
    >>> line = encode_reply(7, "OK", 12.5, -0.25)
    >>> line
    b'7 OK 12.5 -0.25 *3F\\n'
    >>> parse_reply(line).numbers(2)
    (12.5, -0.25)
    """
    parts = [str(int(seq) % 65536), status] + [_number(f) if isinstance(f, float) else str(f) for f in fields]
    body = " ".join(parts).encode("ascii")
    return body + b" *" + checksum(body).encode("ascii") + b"\n"


@dataclass(frozen=True)
class Reply:
    """A parsed reply line.

    Attributes
    ----------
    seq : int
    status : {"OK", "DATA", "ERR"}
    fields : tuple of str
        The words after the status (for ERR: the code, then the message words).
    """

    seq: int
    status: str
    fields: tuple[str, ...]

    def numbers(self, count: int) -> tuple[float, ...]:
        """The first ``count`` fields as floats (RigError if they are not)."""
        if len(self.fields) < count:
            raise RigError(f"reply {self.seq} carries {len(self.fields)} values, expected {count}")
        try:
            values = tuple(float(f) for f in self.fields[:count])
        except ValueError:
            raise RigError(f"reply {self.seq}: values {self.fields[:count]!r} are not numbers") from None
        if not all(math.isfinite(v) for v in values):
            raise RigError(f"reply {self.seq}: values {self.fields[:count]!r} are not finite")
        return values

    @property
    def error(self) -> str:
        return " ".join(self.fields)


def parse_reply(line: bytes) -> Reply:
    """Parse one reply line; anything malformed raises :class:`RigError`, nothing else.

    Raises
    ------
    RigError
        Empty, too long, not ASCII, no checksum, wrong checksum, bad sequence
        number or status.
    """
    if not isinstance(line, (bytes, bytearray)):
        raise RigError(f"reply must be bytes, got {type(line).__name__}")
    raw = bytes(line)
    if len(raw) > MAX_LINE:
        raise RigError(f"reply line of {len(raw)} bytes is longer than {MAX_LINE}: garbage on the line")
    text = raw.rstrip(b"\r\n")
    if not text:
        raise RigError("empty reply line")
    star = text.rfind(b" *")
    if star < 0 or len(text) - star != 4:
        raise RigError(f"reply {text[:40]!r} has no ' *cc' checksum at its end: a garbled line")
    body, given = text[:star], text[star + 2 :]
    try:
        given_s = given.decode("ascii").upper()
        body_s = body.decode("ascii")
    except UnicodeDecodeError:
        raise RigError(f"reply {text[:40]!r} is not ASCII: a garbled line") from None
    if checksum(body) != given_s:
        raise RigError(f"reply {body_s[:40]!r}: checksum {given_s} does not match {checksum(body)}: a garbled line")
    words = body_s.split()
    if len(words) < 2 or not words[0].isdigit() or words[1] not in ("OK", "DATA", "ERR"):
        raise RigError(f"reply {body_s[:40]!r} is not '<seq> OK|DATA|ERR ...'")
    return Reply(int(words[0]), words[1], tuple(words[2:]))


def parse_request(line: bytes, commands: dict[str, int]) -> tuple[int, str, list[float]]:
    """(seq, command, args) of a request line, for the device side.

    Raises
    ------
    ProtocolError
        With code ``BADCMD`` (not a request, or an unknown command) or ``BADARG`` (wrong count,
        not numbers, not finite), and the request's sequence number when it could be read.
    """
    try:
        text = line.decode("ascii").strip()
    except UnicodeDecodeError:
        raise ProtocolError("BADCMD", f"request {bytes(line)[:40]!r} is not ASCII") from None
    words = text.split()
    if len(words) < 2 or not words[0].isdigit():
        seq = int(words[0]) if words and words[0].isdigit() else 0
        raise ProtocolError("BADCMD", f"not '<seq> <COMMAND> ...': {text[:40]!r}", seq)
    seq, cmd, args = int(words[0]), words[1].upper(), words[2:]
    if cmd not in commands:
        raise ProtocolError("BADCMD", f"unknown command {cmd!r}; known: {' '.join(sorted(commands))}", seq)
    if len(args) != commands[cmd]:
        raise ProtocolError("BADARG", f"{cmd} takes {commands[cmd]} argument(s), got {len(args)}", seq)
    try:
        values = [float(a) for a in args]
    except ValueError:
        raise ProtocolError("BADARG", f"{cmd} arguments must be numbers: {' '.join(args)}", seq) from None
    if not all(math.isfinite(v) for v in values):
        raise ProtocolError("BADARG", f"{cmd} arguments must be finite", seq)
    return seq, cmd, values
