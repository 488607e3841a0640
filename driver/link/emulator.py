"""A device emulator: the arm controller and the DAQ of docs/protocol.md, backed by a simulated rig.

Serves both devices on loopback TCP (arm on PORT, DAQ on PORT+1) or on two
pseudo-terminals, one thread per device, with injectable faults.
"""

from __future__ import annotations

import contextlib
import math
import os
import socket
import threading
import time
import tty
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from ..rig import ForceServo, ProtocolError, RigError
from .protocol import ARM_COMMANDS, DAQ_COMMANDS, MAX_LINE, encode_reply, parse_request

if TYPE_CHECKING:
    from sim2d import SimRig, WheelRig

__all__ = ["Faults", "Emulator"]


@dataclass(frozen=True)
class Faults:
    """Faults the emulator injects (all off by default), as a real rig has them.

    Attributes
    ----------
    drop : float
        Probability in [0, 1] that a reply is not sent.
    garble : float
        Probability in [0, 1] that a reply is corrupted (one byte changed).
    delay : float, s
        Added before every reply (0 to 60).
    disconnect_after : int or None
        Close both devices when the arm receives command N+1.
    saturate : float or None, V
        The DAQ's channels clip at ±this value (> 0).
    encoder_stuck : int or None
        From the arm's command N+1 on, POSE reports the jaw angle it had then (a stuck encoder).
    daq_constant : float or None, V
        The DAQ answers every READ, STREAM and ZERO with this voltage on both channels (a dead
        amplifier).
    limit_after : int or None
        From the arm's command N+1 on, MOVE is refused with ``ERR LIMIT`` (the arm at the edge of its
        workspace mid-roll).
    drift : float, V/s
        The channels' zero drifts by this much per second of the emulator's clock (both channels).
    """

    drop: float = 0.0
    garble: float = 0.0
    delay: float = 0.0
    disconnect_after: int | None = None
    saturate: float | None = None
    encoder_stuck: int | None = None
    daq_constant: float | None = None
    limit_after: int | None = None
    drift: float = 0.0

    def __post_init__(self) -> None:
        def bad(name: str, value: object, why: str) -> RigError:
            return RigError(f"fault {name.replace('_', '-')}={value!r}: {why}")

        for name in ("drop", "garble"):
            v = getattr(self, name)
            if not (math.isfinite(v) and 0.0 <= v <= 1.0):
                raise bad(name, v, "a probability must be in [0, 1]")
        if not (math.isfinite(self.delay) and 0.0 <= self.delay <= MAX_DELAY):
            raise bad("delay", self.delay, f"a delay must be in [0, {MAX_DELAY:g}] s")
        for name in ("disconnect_after", "encoder_stuck", "limit_after"):
            v = getattr(self, name)
            if v is not None and (isinstance(v, bool) or not isinstance(v, int) or v < 0):
                raise bad(name, v, "a number of arm commands must be a whole number ≥ 0")
        if self.saturate is not None and not (math.isfinite(self.saturate) and self.saturate > 0):
            raise bad("saturate", self.saturate, "the clipping level must be a positive voltage")
        if self.daq_constant is not None and not (math.isfinite(self.daq_constant) and abs(self.daq_constant) <= 100):
            raise bad("daq_constant", self.daq_constant, "a voltage must be finite, within ±100 V")
        if not (math.isfinite(self.drift) and abs(self.drift) <= 1.0):
            raise bad("drift", self.drift, "a drift must be finite, within ±1 V/s")

    @classmethod
    def parse(cls, specs: Iterable[str] | None) -> Faults:
        """From strings ``name=value`` (the attributes, with ``-`` for ``_``: ``drop=0.05``,
        ``encoder-stuck=200``, ...)."""
        kwargs: dict[str, Any] = {}
        names = {
            "drop": float,
            "garble": float,
            "delay": float,
            "disconnect-after": int,
            "saturate": float,
            "encoder-stuck": int,
            "daq-constant": float,
            "limit-after": int,
            "drift": float,
        }
        for spec in specs or ():
            name, _, value = str(spec).partition("=")
            if name not in names or not value:
                raise RigError(f"fault {spec!r}: use NAME=VALUE with NAME one of {sorted(names)}")
            try:
                kwargs[name.replace("-", "_")] = names[name](value)
            except ValueError:
                raise RigError(f"fault {spec!r}: {value!r} is not a {names[name].__name__}") from None
        return cls(**kwargs)


#: The longest reply delay the emulator injects, s.
MAX_DELAY = 60.0


class Emulator:
    """The two devices over one simulated rig.

    Parameters
    ----------
    rig : sim2d.SimRig
        The simulated rig the commands act on.
    start_pose : (x, y, φ) or None
        Where the hand starts (mm, mm, rad): the operator's jog position.
    faults : Faults
    seed : int
        Seeds the fault injection.
    """

    def __init__(
        self,
        rig: SimRig | WheelRig,
        *,
        start_pose: tuple[float, float, float] | None = None,
        faults: Faults = Faults(),
        seed: int = 0,
    ) -> None:
        self.rig = rig
        self.faults = faults
        self.rng = np.random.default_rng(seed)
        self.lock = threading.Lock()
        self.arm_commands = 0
        self.stopped = threading.Event()
        self.zero = (0.0, 0.0)
        self.input_range = 10.0  # V: the DAQ's input range, reported by STATUS
        self._closers: list[Callable[..., object]] = []
        self._stuck_phi: float | None = None  # the angle a stuck encoder keeps reporting, rad
        self._t0 = time.monotonic()  # the drifting zero's clock
        if start_pose is not None:
            rig.move(*start_pose)

    # ------------------------------------------------------------ devices
    def _arm(self, seq: int, cmd: str, args: list[float]) -> list[bytes]:
        f = self.faults
        if f.encoder_stuck is not None and self.arm_commands > f.encoder_stuck and self._stuck_phi is None:
            self._stuck_phi = self.rig.pose()[2]
        if cmd == "MOVE":
            if f.limit_after is not None and self.arm_commands > f.limit_after:
                return [encode_reply(seq, "ERR", "LIMIT", "outside_the_workspace")]
            x, y, phi_deg = args
            self.rig.move(x, y, math.radians(phi_deg))
            return [encode_reply(seq, "OK")]
        if cmd == "POSE":
            x, y, phi = self.rig.pose()
            if self._stuck_phi is not None:
                phi = self._stuck_phi
            return [encode_reply(seq, "OK", float(x), float(y), float(math.degrees(phi)))]
        if cmd == "STOP":
            return [encode_reply(seq, "OK")]
        if cmd == "AXLE":
            if not callable(getattr(self.rig, "axle", None)):
                return [encode_reply(seq, "ERR", "UNSUPPORTED", "this hand has no wheel on an axle encoder")]
            return [encode_reply(seq, "OK", float(math.degrees(cast("WheelRig", self.rig).axle())))]
        if cmd == "SERVO":
            target, gain, guard, ms = args
            if not (target > 0 and gain >= 0 and guard in (0, 1) and 1 <= ms <= 10000):
                return [encode_reply(seq, "ERR", "BADARG", "SERVO target>0 gain>=0 guard 0|1 ms 1..10000")]
            if not isinstance(self.rig, ForceServo):
                return [encode_reply(seq, "ERR", "UNSUPPORTED", "this arm has no force servo")]
            try:
                r = self.rig.servo(float(target), float(gain), guard=bool(guard), duration=ms / 1000.0)
            except Exception as exc:  # the arm refuses, it does not crash
                return [encode_reply(seq, "ERR", "FAULT", str(exc).replace(" ", "_")[:80])]
            return [encode_reply(seq, "OK", r["dv1"], r["dv1_std"], float(r["contact_lost"]), r["min_energy"])]
        return [encode_reply(seq, "OK", "READY")]

    def _sample(self, n: int) -> tuple[float, float]:
        if self.faults.daq_constant is not None:
            return float(self.faults.daq_constant), float(self.faults.daq_constant)
        v1, v2 = self.rig.read(n)
        drift = self.faults.drift * (time.monotonic() - self._t0)
        v1, v2 = v1 - self.zero[0] + drift, v2 - self.zero[1] + drift
        s = self.faults.saturate
        if s is not None:
            v1, v2 = float(np.clip(v1, -s, s)), float(np.clip(v2, -s, s))
        return float(v1), float(v2)

    def _daq(self, seq: int, cmd: str, args: list[float]) -> list[bytes]:
        if cmd == "READ":
            n = int(args[0])
            if not 1 <= n <= 10000:
                return [encode_reply(seq, "ERR", "BADARG", "READ n must be in 1..10000")]
            return [encode_reply(seq, "OK", *self._sample(n))]
        if cmd == "STREAM":
            n = int(args[0])
            if not 1 <= n <= 10000:
                return [encode_reply(seq, "ERR", "BADARG", "STREAM n must be in 1..10000")]
            return [encode_reply(seq, "DATA", *self._sample(1)) for _ in range(n)] + [encode_reply(seq, "OK")]
        if cmd == "ZERO":
            if self.faults.daq_constant is None:
                self.zero = self.rig.read(256)
            return [encode_reply(seq, "OK")]
        return [encode_reply(seq, "OK", "READY", float(self.faults.saturate or self.input_range))]

    def handle(self, device: str, line: bytes) -> list[bytes]:
        """Replies to one request line of ``device`` ("arm" or "daq")."""
        commands = ARM_COMMANDS if device == "arm" else DAQ_COMMANDS
        try:
            seq, cmd, args = parse_request(line, commands)
        except ProtocolError as exc:
            return [encode_reply(exc.seq, "ERR", exc.code, exc.message.replace("\n", " ")[:120])]
        with self.lock:
            if device == "arm":
                self.arm_commands += 1
                if self.faults.disconnect_after is not None and self.arm_commands > self.faults.disconnect_after:
                    self.close()
                    return []
                return self._arm(seq, cmd, args)
            return self._daq(seq, cmd, args)

    def _faulty(self, replies: list[bytes]) -> list[bytes]:
        out = []
        for r in replies:
            if self.faults.drop and self.rng.random() < self.faults.drop:
                continue
            if self.faults.garble and self.rng.random() < self.faults.garble:
                b = bytearray(r)
                i = int(self.rng.integers(0, max(1, len(b) - 1)))
                b[i] = (b[i] + 1 + int(self.rng.integers(0, 90))) % 95 + 32
                r = bytes(b)
            out.append(r)
        return out

    def _serve(self, device: str, read: Callable[[], bytes], write: Callable[[bytes], object]) -> None:
        buf = b""
        while not self.stopped.is_set():
            try:
                chunk = read()
            except OSError:
                return
            if not chunk:
                return
            buf += chunk
            while b"\n" in buf:
                line, buf = buf.split(b"\n", 1)
                if len(line) > MAX_LINE:
                    continue
                replies = self._faulty(self.handle(device, line))
                if self.stopped.is_set():
                    return
                if self.faults.delay:
                    self.stopped.wait(self.faults.delay)
                try:
                    for r in replies:
                        write(r)
                except OSError:
                    return
            if len(buf) > 4 * MAX_LINE:
                buf = b""

    # ---------------------------------------------------------- transports
    def serve_tcp(self, port: int, host: str = "127.0.0.1") -> tuple[str, ...]:
        """Listen on host:port (arm) and host:port+1 (DAQ); returns the two URLs.

        ``port=0`` lets the system pick two free ports (for tests).
        """
        if not (port == 0 or 1 <= port <= 65534):
            raise RigError(f"port {port}: use 1 to 65534 (the DAQ takes the next port), or 0 for any free one")
        urls = []
        for device, p in (("arm", port), ("daq", port + 1 if port else 0)):
            srv = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
            srv.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            try:
                srv.bind((host, p))
            except OSError as exc:
                srv.close()
                self.close()
                why = exc.strerror or exc
                raise RigError(f"cannot serve the {device} on {host}:{p}: {why} (another program has it?)") from None
            srv.listen(4)
            srv.settimeout(0.2)
            self._closers.append(srv.close)
            threading.Thread(target=self._accept, args=(device, srv), daemon=True).start()
            urls.append(f"socket://{host}:{srv.getsockname()[1]}")
        return tuple(urls)

    def _accept(self, device: str, srv: socket.socket) -> None:
        while not self.stopped.is_set():
            try:
                conn, _ = srv.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self._closers.append(conn.close)

            def shutdown(c: socket.socket = conn) -> None:
                with contextlib.suppress(OSError):
                    c.shutdown(socket.SHUT_RDWR)

            self._closers.append(shutdown)
            threading.Thread(
                target=self._serve, args=(device, lambda c=conn: c.recv(4096), conn.sendall), daemon=True
            ).start()

    def serve_pty(self) -> tuple[str, ...]:
        """Serve on two pseudo-terminals; returns their device paths (arm, DAQ)."""
        paths = []
        for device in ("arm", "daq"):
            master, slave = os.openpty()
            tty.setraw(master)
            tty.setraw(slave)
            self._closers.append(lambda m=master: os.close(m))
            self._closers.append(lambda s=slave: os.close(s))
            threading.Thread(
                target=self._serve,
                args=(device, lambda m=master: os.read(m, 4096), lambda data, m=master: os.write(m, data)),
                daemon=True,
            ).start()
            paths.append(os.ttyname(slave))
        return tuple(paths)

    def close(self) -> None:
        """Stop serving and close every connection (a pulled cable)."""
        self.stopped.set()
        for c in reversed(self._closers):
            with contextlib.suppress(OSError):
                c()
        self._closers.clear()
