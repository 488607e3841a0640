"""``SerialRig``: the arm and the DAQ over pyserial URLs, speaking docs/protocol.md; satisfies ``Rig``.

Every command has a deadline; a missing, garbled or stale reply is retried a
bounded number of times, then the run stops with a :class:`RigError` saying
what happened. Moves outside the workspace are refused before they are sent;
a reading with Δv1 above the overload limit stops the run. :meth:`safe_stop`
stops the arm and backs the jaw off the part; use the rig as a context
manager to get it on any error.
"""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import signal
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import IO, Any, Literal, Self

import serial

from ..rig import Pose, ProtocolError, RigError, TransportError
from .lockfile import LockHeld, hold_lock
from .protocol import MAX_LINE, Reply, encode_request, parse_reply
from .signals import handling

__all__ = ["LineReader", "SerialRig", "Workspace"]

#: Each URL's port still closing in this process. pyserial sleeps 0.3 s after it has closed a socket://
#: port, room for the server to take the next connection: a rig opening that URL again waits for the
#: sleep to end, the rig closing it only until the port is shut.
_closing: dict[str, threading.Thread] = {}
_closing_lock = threading.Lock()


@dataclass(frozen=True)
class Workspace:
    """Reachable hand poses: x, y in mm, φ in rad (a box; defaults are generous)."""

    x: tuple[float, float] = (-500.0, 500.0)
    y: tuple[float, float] = (-500.0, 500.0)
    phi: tuple[float, float] = (-4 * math.pi, 4 * math.pi)

    def check(self, x: float, y: float, phi: float) -> None:
        for name, v, (lo, hi) in (("x", x, self.x), ("y", y, self.y), ("phi", phi, self.phi)):
            if not (math.isfinite(v) and lo <= v <= hi):
                raise RigError(f"move refused: {name}={v!r} is outside the workspace [{lo}, {hi}]")


class LineReader:
    """A port's replies, a line at a time.

    What the port holds is taken at once and the rest kept for the next line: pyserial's ``read_until``
    takes a byte per call, with a wait and a system call for each (three quarters of a reading's time
    over a local socket).
    """

    def __init__(self, port: Any) -> None:
        self.port = port
        self.pending = b""  # read past the last line returned

    def readline(self, deadline: float) -> bytes:
        """The next line with its newline; else what came of it by ``deadline`` (``time.monotonic()``, s),
        or without a newline its first ``MAX_LINE + 1`` bytes (too long: the rest is the next line).

        What the port holds is taken even past the deadline: a reply that came in time is not lost to a
        process that was kept from running."""
        buf = self.pending
        while True:
            end = buf.find(b"\n", 0, MAX_LINE + 1)
            if end >= 0 or len(buf) > MAX_LINE:
                cut = end + 1 if end >= 0 else MAX_LINE + 1
                self.pending = buf[cut:]
                return buf[:cut]
            self.port.timeout = max(deadline - time.monotonic(), 0.0)
            first = self.port.read(1)  # waits for the line to go on, until the deadline
            if not first:
                self.pending = b""
                return buf
            self.port.timeout = 0
            buf += first + self.port.read(4096)  # and whatever came with it


class SerialRig:
    """The real rig (or its emulator) over two pyserial URLs.

    Parameters
    ----------
    arm_url, daq_url : str
        pyserial URLs: a device path (``/dev/ttyUSB0``), ``socket://host:port``,
        ``loop://``.
    timeout : float, s
        Deadline of a reply (a MOVE gets ``timeout`` plus the move's duration at
        ``move_speed``).
    retries : int
        Further tries of a command whose reply is missing or garbled.
    overload : float, V
        Largest raw v1 allowed; above it the run stops and the jaw backs off.
    backoff : float, mm
        How far :meth:`safe_stop` backs the jaw off along its normal.
    workspace : Workspace
    move_speed : float, mm/s
        The arm's speed, for MOVE deadlines.
    log : callable or None
        Called with a dict for every command and reading (see :mod:`driver.records.runlog`).
    """

    def __init__(
        self,
        arm_url: str,
        daq_url: str,
        *,
        timeout: float = 2.0,
        retries: int = 2,
        overload: float = 2.0,
        backoff: float = 5.0,
        workspace: Workspace = Workspace(),
        move_speed: float = 20.0,
        log: Callable[[dict[str, Any]], object] | None = None,
        baudrate: int = 115200,
    ) -> None:
        self.timeout = float(timeout)
        self.retries = int(retries)
        self.overload = float(overload)
        self.backoff = float(backoff)
        self.workspace = workspace
        self.move_speed = float(move_speed)
        self.log = log
        self._seq = 0
        self._commanded: tuple[float, float, float] | None = None
        self.ports: dict[str, Any] = {}
        self._lines: dict[str, LineReader] = {}
        self._urls = {"arm": arm_url, "daq": daq_url}
        self._locks: list[IO[str]] = []
        try:
            for name, url in (("arm", arm_url), ("daq", daq_url)):
                self._locks.append(_device_lock(name, url))
                with _closing_lock:
                    closing = _closing.pop(url, None)
                if closing is not None:
                    closing.join()
                # a local device is also locked by the OS (pyserial's flock), against other programs
                local = "://" not in url
                self.ports[name] = serial.serial_for_url(
                    url,
                    timeout=self.timeout,
                    write_timeout=self.timeout,
                    baudrate=baudrate,
                    **({"exclusive": True} if local and os.name == "posix" else {}),
                )
                self._lines[name] = LineReader(self.ports[name])
        except (serial.SerialException, ValueError) as exc:
            self.close()
            raise RigError(f"cannot open the {name} at {url}: {_open_problem(url, exc)}") from None
        except RigError:
            self.close()
            raise
        # the DAQ reports its input range: readings at its ends are saturated
        try:
            status = self._transact("daq", "STATUS")
            self.input_range = 10.0
            if len(status.fields) >= 2:
                self.input_range = float(Reply(status.seq, "OK", status.fields[1:]).numbers(1)[0])
            elif len(self._transact("arm", "STATUS").fields) >= 2:
                # a DAQ reports its input range with STATUS, an arm does not: they are the other way round
                raise RigError(
                    f"--arm {arm_url} answers STATUS as a DAQ (with an input range) and --daq {daq_url} as an "
                    "arm (without one): the two are swapped; swap --arm and --daq"
                )
        except RigError:
            self.close()
            raise

    # ------------------------------------------------------------ transport
    def _transact(self, device: str, command: str, *args: float, timeout: float | None = None) -> Reply:
        port = self.ports[device]
        timeout = self.timeout if timeout is None else timeout
        problem = "no reply"
        for attempt in range(self.retries + 1):
            self._seq = (self._seq + 1) % 65536
            seq = self._seq
            try:
                port.write(encode_request(seq, command, *args))
                port.flush()
                deadline = time.monotonic() + timeout
                while True:
                    line = self._lines[device].readline(deadline)
                    if not line:
                        problem = f"no reply within {timeout:.1f} s"
                        break
                    if not line.endswith(b"\n"):
                        problem = f"a partial reply {line[:40]!r} (timeout or line too long)"
                        break
                    try:
                        reply = parse_reply(line)
                    except RigError as exc:
                        problem = str(exc)
                        break
                    if reply.seq != seq:
                        continue  # a late reply to an earlier try: skip it
                    if reply.status == "ERR":
                        code = reply.fields[0] if reply.fields else "ERR"
                        raise ProtocolError(
                            code, f"the {device} refused {command}: {' '.join(reply.fields[1:])}", reply.seq
                        )
                    if reply.status == "DATA":
                        continue
                    return reply
            except RigError:
                raise  # the device's own refusal (ERR): not a connection failure
            except serial.SerialException as exc:
                raise TransportError(f"the {device} connection failed during {command}: {exc}") from None
            except OSError as exc:
                raise TransportError(f"the {device} connection failed during {command}: {exc}") from None
            self._emit({"event": "retry", "device": device, "command": command, "try": attempt + 1, "problem": problem})
        raise TransportError(f"the {device} did not answer {command} after {self.retries + 1} tries: {problem}")

    def _emit(self, event: dict[str, Any]) -> None:
        if self.log is not None:
            self.log(dict(event, time=time.time()))

    # ------------------------------------------------------------------ Rig
    def move(self, x: float, y: float, phi: float) -> None:
        """MOVE to (x, y) mm, φ rad; returns when the arm reports arrival."""
        self.workspace.check(x, y, phi)
        distance = 0.0 if self._commanded is None else math.hypot(x - self._commanded[0], y - self._commanded[1])
        self._transact(
            "arm", "MOVE", float(x), float(y), math.degrees(phi), timeout=self.timeout + distance / self.move_speed
        )
        self._commanded = (float(x), float(y), float(phi))

    def pose(self) -> Pose:
        """POSE: the arm's (x mm, y mm, φ rad)."""
        x, y, phi_deg = self._transact("arm", "POSE").numbers(3)
        return Pose(x, y, math.radians(phi_deg))

    def axle(self) -> float:
        """AXLE: a wheel finger's axle encoder, the disc's angle relative to the hand (rad). An arm whose
        hand has no wheel answers ``ERR UNSUPPORTED`` (:class:`ProtocolError`)."""
        (psi_deg,) = self._transact("arm", "AXLE").numbers(1)
        psi = math.radians(psi_deg)
        self._emit({"event": "axle", "psi": psi})
        return psi

    def has_wheel(self) -> bool:
        """Whether the hand has a wheel on an axle encoder: AXLE answers. An arm that refuses it
        (``ERR UNSUPPORTED``, or ``ERR BADCMD`` from a controller older than the wheel) has none."""
        try:
            self._transact("arm", "AXLE")
        except ProtocolError:
            return False
        return True

    def read(self, n: int = 32) -> tuple[float, float]:
        """READ n: averaged (v1, v2) in volts; stops the run above the overload limit."""
        v1, v2 = self._transact("daq", "READ", int(n)).numbers(2)
        self._emit({"event": "sample", "v1": v1, "v2": v2, "n": int(n)})
        if max(abs(v1), abs(v2)) >= 0.999 * self.input_range:
            self.safe_stop()
            raise RigError(
                f"the sensor saturated (v1 = {v1:.4g} V, v2 = {v2:.4g} V at the DAQ's "
                f"±{self.input_range:g} V range): stopped and backed off"
            )
        if v1 > self.overload:
            self.safe_stop()
            raise RigError(f"v1 = {v1:.4g} V is above the overload limit {self.overload} V: stopped and backed off")
        return v1, v2

    def servo(self, target: float, gain: float, *, guard: bool = True, duration: float = 0.5) -> dict[str, Any]:
        """SERVO: the arm holds Δv1 = ``target`` V with its own 1 kHz force loop for ``duration`` s.

        ``guard`` switches on the controller's passivity observer/controller on
        the loop's port. Returns the same dict as :meth:`sim2d.SimRig.servo`.
        """
        ms = int(round(duration * 1000))
        dv1, std, lost, energy = self._transact(
            "arm", "SERVO", float(target), float(gain), int(bool(guard)), ms, timeout=self.timeout + duration
        ).numbers(4)
        result = {"dv1": dv1, "dv1_std": std, "contact_lost": int(lost), "min_energy": energy, "guard": bool(guard)}
        self._emit(dict(result, event="servo", target=float(target), gain=float(gain)))
        return result

    # --------------------------------------------------------------- safety
    def stop(self) -> None:
        """STOP the arm."""
        self._transact("arm", "STOP")

    def safe_stop(self) -> str:
        """Best effort: stop the arm and back the jaw ``backoff`` mm off the part. Never raises; a
        Ctrl-C or SIGTERM while it runs is held until it is done. Returns what really happened, as a
        sentence for the user (also logged as the ``safe_stop`` event)."""
        done: dict[str, str] = {}
        # a second Ctrl-C (or SIGTERM) must not cut the safe stop short; it is always on the way out
        # (its caller raises next), so a signal that came meanwhile has nothing left to stop
        with handling(("SIGINT", "SIGTERM", "SIGHUP"), signal.SIG_IGN):
            for name, action in (("stop", self.stop), ("back_off", self._back_off)):
                try:
                    action()
                    done[name] = ""
                except (RigError, OSError, serial.SerialException) as exc:
                    done[name] = str(exc)
        if self._commanded is None:
            done["back_off"] = "no MOVE had been sent, so there was nothing to back off from"
        stopped = "the arm was stopped" if not done["stop"] else f"STOP failed ({done['stop']})"
        if not done["back_off"]:
            backed = f"the jaw was backed off {self.backoff:g} mm"
        elif self._commanded is None:
            backed = done["back_off"]
        else:
            backed = f"backing the jaw off failed ({done['back_off']}): jog it clear of the part by hand"
        self._emit({"event": "safe_stop", "stop_problem": done["stop"], "back_off_problem": done["back_off"]})
        return f"{stopped}; {backed}"

    def _back_off(self) -> None:
        if self._commanded is None:
            return
        x, y, phi = self._commanded
        d = self.backoff
        self.move(x + d * math.sin(phi), y - d * math.cos(phi), phi)

    def close(self) -> None:
        # each port closes on a thread of its own, waited for until the port is shut (pyserial marks it
        # closed once its socket or descriptor is), not through pyserial's sleep after a socket:// port
        # (see _closing); a port that does not say whether it is open is waited for to the end
        closers = []
        for name, port in self.ports.items():
            if not getattr(port, "is_open", True):
                continue  # closed before: its sleep, if any, is already waited for where it matters
            thread = threading.Thread(target=_close_quietly, args=(port,), name=f"close {name}", daemon=True)
            thread.start()
            with _closing_lock:
                _closing[self._urls[name]] = thread
            closers.append((port, thread))
        for port, thread in closers:
            while thread.is_alive() and getattr(port, "is_open", True):
                thread.join(0.002)
        for lock in self._locks:
            with contextlib.suppress(OSError):
                lock.close()
        self._locks = []

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> Literal[False]:
        if exc_type is not None:
            outcome = self.safe_stop()
            if isinstance(exc, BaseException):
                exc.add_note(outcome)  # the CLI prints it after the error: what the host really did
        self.close()
        return False


def _close_quietly(port: Any) -> None:
    with contextlib.suppress(OSError, serial.SerialException):
        port.close()


def _open_problem(url: str, exc: Exception) -> str:
    """Why pyserial could not open ``url``, in words that say what to fix (its own text is often the
    parser's, e.g. "'debug|info|warning|error'" for a socket URL whose port is not a number)."""
    if url.startswith("socket://"):
        host, _, port = url[len("socket://") :].partition("/")[0].rpartition(":")
        if not host or not port.isdigit() or not 0 < int(port) < 65536:
            return "a socket URL is socket://HOST:PORT, PORT a number from 1 to 65535"
    errno = getattr(exc, "errno", None)
    if errno == 2 or "No such file" in str(exc):
        return "no such device (is it plugged in? `ls /dev/tty*` lists the serial ports)"
    if errno == 13 or "Permission denied" in str(exc):
        return "permission denied (add yourself to the group that owns the port, e.g. dialout)"
    if errno == 111 or "Connection refused" in str(exc):
        return "connection refused (is the device, or `rolltouch emulate`, listening there?)"
    return str(exc)


def _device_lock(name: str, url: str) -> IO[str]:
    """An exclusive lock on ``url`` for this process (a lock file in the temporary folder, whatever
    the transport): two host processes driving one arm would interleave their commands and replies.
    Raises :class:`RigError` naming the holder when another process has it."""
    path = Path(tempfile.gettempdir()) / f"rolltouch-{hashlib.sha1(url.encode()).hexdigest()[:16]}.lock"
    try:
        return hold_lock(path, f"rolltouch pid {os.getpid()}")
    except LockHeld as held:
        raise RigError(
            f"the {name} at {url} is in use by {held.holder} (lock {path}): two hosts driving one arm would "
            "interleave their commands; stop the other run first"
        ) from None
