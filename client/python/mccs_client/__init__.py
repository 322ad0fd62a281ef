"""The scene's library for an mccs haptic device, in Python.

ctypes over the C ABI of ``libmccs_client`` (client/include/mccs.h): the same code as the
Rust and C clients, no compiler needed at install time. The library is found, in order,
at ``$MCCS_CLIENT_LIB``, beside this package, or by the system's loader
(``LD_LIBRARY_PATH``, ``DYLD_LIBRARY_PATH``, ``PATH``)::

    from mccs_client import Device

    with Device("unix:/tmp/mccs.sock") as device:
        print(device.info())
        device.load_tissue("params/table2.toml", friction=(0.6, 0.4))
        device.watch(10)
        with device.armed():          # keepalives from the library's thread
            time.sleep(2)
            print(device.telemetry())
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import math
import os
from dataclasses import dataclass
from typing import Iterator, List, Optional, Tuple

__all__ = [
    "Device",
    "MccsError",
    "Info",
    "Status",
    "Telemetry",
    "MeshNode",
    "BlackBox",
    "BoxTick",
    "FLAGS",
    "BOX_FLAGS",
    "RESET_FLAGS",
]

OK = 0
ERR_ARGUMENT = -1
ERR_CONNECT = -2
ERR_PROTOCOL = -3
ERR_REFUSED = -4
ERR_TIMEOUT = -5
ERR_LOST = -6
ERR_TISSUE = -7
ERR_NO_DATA = -8
ERR_BUFFER = -9
ERR_INTERNAL = -10

#: Telemetry flag bits, by name.
FLAGS = {
    "contact": 1 << 0,
    "slipping": 1 << 1,
    "armed": 1 << 2,
    "fault": 1 << 3,
    "clamped": 1 << 4,
    "homed": 1 << 5,
    "at_limit": 1 << 6,
    "checking": 1 << 7,
    "gain_limited": 1 << 8,
    "thermal": 1 << 9,
}


#: A black box tick's flag bits, by name.
BOX_FLAGS = {
    "homed": 1 << 0,
    "at_limit": 1 << 1,
    "thermal": 1 << 2,
    "clamped": 1 << 3,
    "faulted": 1 << 4,
}

#: The reset's cause bits (the STM32F4's RCC_CSR), by name.
RESET_FLAGS = {
    "BOR": 1 << 25,
    "PIN": 1 << 26,
    "POR": 1 << 27,
    "SFT": 1 << 28,
    "IWDG": 1 << 29,
    "WWDG": 1 << 30,
    "LPWR": 1 << 31,
}


class MccsError(Exception):
    """A call failed: ``code`` is the C ABI's (``ERR_*``), the message the device's or
    the library's one line."""

    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code


class _Info(ctypes.Structure):
    _fields_ = [
        ("device_kind", ctypes.c_int),
        ("simulated", ctypes.c_int),
        ("roaming", ctypes.c_int),
        ("tick_hz", ctypes.c_uint32),
        ("grid", ctypes.c_uint32),
        ("tissue_w", ctypes.c_uint32),
        ("tissue_h", ctypes.c_uint32),
        ("spacing_mm", ctypes.c_double),
        ("knots", ctypes.c_uint32),
        ("tissue_hash", ctypes.c_uint32),
        ("mu_s", ctypes.c_double),
        ("mu_k", ctypes.c_double),
        ("force_clamp_n", ctypes.c_double),
        ("workspace_lo_mm", ctypes.c_double * 3),
        ("workspace_hi_mm", ctypes.c_double * 3),
        ("baud", ctypes.c_uint32),
        ("telemetry_least_every", ctypes.c_uint32),
        ("mesh_least_every", ctypes.c_uint32),
    ]


class _Status(ctypes.Structure):
    _fields_ = [
        ("ticks", ctypes.c_uint32),
        ("overruns", ctypes.c_uint32),
        ("bad_frames", ctypes.c_uint32),
        ("dropped_telemetry", ctypes.c_uint32),
        ("armed", ctypes.c_int),
        ("fault", ctypes.c_int),
        ("gain", ctypes.c_double),
    ]


class _Telemetry(ctypes.Structure):
    _fields_ = [
        ("seq", ctypes.c_uint32),
        ("tick", ctypes.c_uint32),
        ("received_s", ctypes.c_double),
        ("probe_mm", ctypes.c_double * 3),
        ("force_n", ctypes.c_double * 3),
        ("gain", ctypes.c_double),
        ("flags", ctypes.c_uint32),
        ("duties", ctypes.c_double * 3),
        ("proxy_mm", ctypes.c_double * 3),
    ]


class _MeshNode(ctypes.Structure):
    _fields_ = [
        ("i", ctypes.c_uint32),
        ("j", ctypes.c_uint32),
        ("position_mm", ctypes.c_double * 3),
    ]


class _BlackBox(ctypes.Structure):
    _fields_ = [
        ("kept", ctypes.c_int),
        ("stopped_by", ctypes.c_int),
        ("part", ctypes.c_int),
        ("stop_tick", ctypes.c_uint32),
        ("ended_by", ctypes.c_int),
        ("end_tick", ctypes.c_uint32),
        ("pc", ctypes.c_uint32),
        ("reset_flags", ctypes.c_uint32),
        ("ticks", ctypes.c_uint32),
    ]


class _BoxTick(ctypes.Structure):
    _fields_ = [
        ("tick", ctypes.c_uint32),
        ("counts", ctypes.c_int32 * 3),
        ("force_n", ctypes.c_double * 3),
        ("duties", ctypes.c_double * 3),
        ("gain", ctypes.c_double),
        ("flags", ctypes.c_uint32),
    ]


@dataclass(frozen=True)
class Info:
    """What the device says of itself."""

    device: str
    simulated: bool
    roaming: bool
    tick_hz: int
    grid: int
    tissue: Tuple[int, int]
    spacing_mm: float
    knots: int
    tissue_hash: int
    friction: Tuple[float, float]
    force_clamp_n: float
    workspace_mm: Tuple[Tuple[float, float, float], Tuple[float, float, float]]
    baud: int
    telemetry_least_every: int
    mesh_least_every: int


@dataclass(frozen=True)
class Status:
    """The device's counters and state."""

    ticks: int
    overruns: int
    bad_frames: int
    dropped_telemetry: int
    armed: bool
    fault: int
    gain: float


@dataclass(frozen=True)
class Telemetry:
    """A live tick, in units; ``flags`` by name in ``flag(name)``."""

    seq: int
    tick: int
    received_s: float
    probe_mm: Tuple[float, float, float]
    force_n: Tuple[float, float, float]
    gain: float
    flags: int
    duties: Tuple[float, float, float]
    proxy_mm: Tuple[float, float, float]

    def flag(self, name: str) -> bool:
        """Whether flag ``name`` (a key of ``FLAGS``) is set."""
        return bool(self.flags & FLAGS[name])


@dataclass(frozen=True)
class MeshNode:
    """A node of the live mesh: its place in the surface grid, its position (mm)."""

    i: int
    j: int
    position_mm: Tuple[float, float, float]


def _number(x: float) -> str:
    """A float as the CSV writes it (Rust's shortest form: ``1``, ``-0.25``)."""
    text = repr(float(x))
    return text[:-2] if text.endswith(".0") else text


@dataclass(frozen=True)
class BoxTick:
    """One tick of a black box: counts, force (N), duties and gain (fractions of
    full), flags (``BOX_FLAGS``)."""

    tick: int
    counts: Tuple[int, int, int]
    force_n: Tuple[float, float, float]
    duties: Tuple[float, float, float]
    gain: float
    flags: int

    #: The CSV's columns (as ``mccs link blackbox`` prints them).
    CSV_HEADER = "tick,count_a,count_b,count_c,fx_n,fy_n,fz_n,duty_a,duty_b,duty_c,gain,flags"

    def flag(self, name: str) -> bool:
        """Whether flag ``name`` (a key of ``BOX_FLAGS``) is set."""
        return bool(self.flags & BOX_FLAGS[name])

    def csv_row(self) -> str:
        """The tick as ``mccs link blackbox`` prints its row."""
        return ",".join(
            [str(self.tick), *map(str, self.counts), *map(_number, self.force_n)]
            + [f"{x:.5f}" for x in (*self.duties, self.gain)]
            + [str(self.flags)]
        )


@dataclass(frozen=True)
class BlackBox:
    """What a device kept of its run before its last reset (docs/safety.md, "The black
    box"): what first stopped the force and on which part (the board's code), what
    ended the run, the reset's cause, its last ticks oldest first. ``kept`` is False
    after a power-on (the rest empty)."""

    kept: bool
    stopped_by: str
    part: int
    stop_tick: int
    ended_by: str
    end_tick: int
    pc: int
    reset_flags: int
    ticks: List[BoxTick]

    def reset_names(self) -> str:
        """The reset's flags by name, ``+``-joined (``none`` where the chip reported none)."""
        names = [n for n, bit in RESET_FLAGS.items() if self.reset_flags & bit]
        return "+".join(names) if names else "none"

    def line(self) -> str:
        """One line, as ``mccs link blackbox`` prints it (the part by its code)."""
        if not self.kept:
            return "blackbox kept=false"
        return (
            f"blackbox kept=true stopped_by={self.stopped_by} part={self.part} stop_tick={self.stop_tick} "
            f"ended_by={self.ended_by} end_tick={self.end_tick} pc=0x{self.pc:08x} reset={self.reset_names()} "
            f"reset_flags=0x{self.reset_flags:08x} ticks={len(self.ticks)}"
        )


def _load() -> ctypes.CDLL:
    names = {"posix": "libmccs_client.so", "nt": "mccs_client.dll"}
    if os.uname().sysname == "Darwin" if hasattr(os, "uname") else False:
        names["posix"] = "libmccs_client.dylib"
    candidates: List[str] = []
    env = os.environ.get("MCCS_CLIENT_LIB")
    if env:
        candidates.append(env)
    here = os.path.dirname(os.path.abspath(__file__))
    candidates.append(os.path.join(here, names.get(os.name, "libmccs_client.so")))
    found = ctypes.util.find_library("mccs_client")
    if found:
        candidates.append(found)
    errors = []
    for c in candidates:
        try:
            return ctypes.CDLL(c)
        except OSError as e:
            errors.append(f"{c}: {e}")
    raise ImportError(
        "mccs_client: libmccs_client not found (build it with `cargo build --release -p "
        "mccs-client` and set MCCS_CLIENT_LIB to it): " + "; ".join(errors)
    )


_lib = _load()
_lib.mccs_last_error.restype = ctypes.c_char_p
_lib.mccs_open.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_void_p)]
_lib.mccs_close.argtypes = [ctypes.c_void_p]
_lib.mccs_close.restype = None
_lib.mccs_info.argtypes = [ctypes.c_void_p, ctypes.POINTER(_Info)]
_lib.mccs_status.argtypes = [ctypes.c_void_p, ctypes.POINTER(_Status)]
_lib.mccs_load_tissue.argtypes = [
    ctypes.c_void_p,
    ctypes.c_char_p,
    ctypes.c_double,
    ctypes.c_double,
    ctypes.POINTER(ctypes.c_uint32),
]
_lib.mccs_set_pose.argtypes = [ctypes.c_void_p] + [ctypes.c_double] * 6
_lib.mccs_arm.argtypes = [ctypes.c_void_p]
_lib.mccs_disarm.argtypes = [ctypes.c_void_p]
_lib.mccs_watch.argtypes = [ctypes.c_void_p, ctypes.c_uint16]
_lib.mccs_telemetry.argtypes = [ctypes.c_void_p, ctypes.POINTER(_Telemetry)]
_lib.mccs_watch_mesh.argtypes = [ctypes.c_void_p, ctypes.c_uint16]
_lib.mccs_mesh.argtypes = [
    ctypes.c_void_p,
    ctypes.POINTER(_MeshNode),
    ctypes.c_size_t,
    ctypes.POINTER(ctypes.c_size_t),
    ctypes.POINTER(ctypes.c_uint32),
]

_lib.mccs_black_box.argtypes = [
    ctypes.c_void_p,
    ctypes.POINTER(_BlackBox),
    ctypes.POINTER(_BoxTick),
    ctypes.c_size_t,
    ctypes.POINTER(ctypes.c_size_t),
]
_lib.mccs_stop_cause_name.argtypes = [ctypes.c_int]
_lib.mccs_stop_cause_name.restype = ctypes.c_char_p


def _cause(code: int) -> str:
    name = _lib.mccs_stop_cause_name(code)
    return name.decode() if name else f"cause-{code}"


def _text(name: str, value: str) -> bytes:
    """``value`` as the C string the library reads: ctypes would cut it at a NUL byte,
    silently (``"tcp:a:1\\0b"`` opened ``tcp:a:1``), so one is refused."""
    if not isinstance(value, str):
        raise MccsError(ERR_ARGUMENT, f"{name}: must be a str, not {type(value).__name__}")
    if "\0" in value:
        raise MccsError(ERR_ARGUMENT, f"{name}: holds a NUL byte")
    return value.encode()


def _numbers(name: str, values, k: int) -> Tuple[float, ...]:
    """Exactly ``k`` numbers: ctypes takes the six of a pose as one list, so four and two
    would pass as another pose."""
    try:
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise MccsError(ERR_ARGUMENT, f"{name}: must be {k} numbers") from None
    if len(out) != k:
        raise MccsError(ERR_ARGUMENT, f"{name}: must be {k} numbers, not {len(out)}")
    return out


def _period(name: str, every: int) -> int:
    """A period in ticks, 0 … 65535: ctypes would wrap another (-1 as 65535, 70000 as
    4464)."""
    if isinstance(every, bool) or not isinstance(every, int) or not 0 <= every <= 0xFFFF:
        raise MccsError(ERR_ARGUMENT, f"{name}: must be a whole number of ticks, 0 … 65535 (got {every!r})")
    return every


def _check(code: int) -> None:
    if code != OK:
        message = _lib.mccs_last_error() or b""
        raise MccsError(code, message.decode("utf-8", "replace"))


class Device:
    """A session with a device: open, read its facts, load tissues, place them, hold it
    armed, read its telemetry and mesh. A context manager: leaving it closes the session
    (disarming the device if this session armed it)."""

    def __init__(self, addr: str):
        handle = ctypes.c_void_p()
        _check(_lib.mccs_open(_text("addr", addr), ctypes.byref(handle)))
        self._h: Optional[ctypes.c_void_p] = handle

    def __enter__(self) -> "Device":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self) -> None:
        self.close()

    def close(self) -> None:
        """Ends the session (disarms the device if this session armed it)."""
        h, self._h = getattr(self, "_h", None), None
        if h:
            _lib.mccs_close(h)

    def _handle(self) -> ctypes.c_void_p:
        if not self._h:
            raise MccsError(ERR_ARGUMENT, "the device is closed")
        return self._h

    def info(self) -> Info:
        """What the device said of itself when opened."""
        i = _Info()
        _check(_lib.mccs_info(self._handle(), ctypes.byref(i)))
        return Info(
            device="arm" if i.device_kind else "1dof",
            simulated=bool(i.simulated),
            roaming=bool(i.roaming),
            tick_hz=i.tick_hz,
            grid=i.grid,
            tissue=(i.tissue_w, i.tissue_h),
            spacing_mm=i.spacing_mm,
            knots=i.knots,
            tissue_hash=i.tissue_hash,
            friction=(i.mu_s, i.mu_k),
            force_clamp_n=i.force_clamp_n,
            workspace_mm=(tuple(i.workspace_lo_mm), tuple(i.workspace_hi_mm)),
            baud=i.baud,
            telemetry_least_every=i.telemetry_least_every,
            mesh_least_every=i.mesh_least_every,
        )

    def status(self) -> Status:
        """The device's counters and state, asked now."""
        s = _Status()
        _check(_lib.mccs_status(self._handle(), ctypes.byref(s)))
        return Status(s.ticks, s.overruns, s.bad_frames, s.dropped_telemetry, bool(s.armed), s.fault, s.gain)

    def load_tissue(self, path: "str | os.PathLike[str]", friction: Optional[Tuple[float, float]] = None) -> int:
        """Loads a tissue from a parameter ``.toml`` or a table ``.bin``, with friction
        ``(mu_s, mu_k)`` (None: keep the live one's); its hash, once the device runs it.
        The device's refusal is a ``MccsError`` with ``code == ERR_REFUSED``."""
        name = _text("path", os.fspath(path) if isinstance(path, os.PathLike) else path)
        mu_s, mu_k = _numbers("friction", friction, 2) if friction is not None else (math.nan, math.nan)
        h = ctypes.c_uint32()
        _check(_lib.mccs_load_tissue(self._handle(), name, mu_s, mu_k, ctypes.byref(h)))
        return h.value

    def set_pose(self, origin_mm: Tuple[float, float, float], rotation_deg: Tuple[float, float, float] = (0.0, 0.0, 0.0)) -> None:
        """Places the tissue: its origin and a rotation ``Rz Ry Rx`` in degrees."""
        origin = _numbers("origin_mm", origin_mm, 3)
        rotation = _numbers("rotation_deg", rotation_deg, 3)
        _check(_lib.mccs_set_pose(self._handle(), *origin, *rotation))

    def arm(self) -> None:
        """Arms the device; the library keeps it alive until ``disarm`` or ``close``."""
        _check(_lib.mccs_arm(self._handle()))

    def disarm(self) -> None:
        """Force to zero at once."""
        _check(_lib.mccs_disarm(self._handle()))

    @contextlib.contextmanager
    def armed(self) -> Iterator["Device"]:
        """Holds the device armed for the ``with`` block."""
        self.arm()
        try:
            yield self
        finally:
            self.disarm()

    def watch(self, every: int) -> None:
        """Telemetry every ``every`` ticks (0: none)."""
        _check(_lib.mccs_watch(self._handle(), _period("every", every)))

    def telemetry(self) -> Optional[Telemetry]:
        """The latest telemetry sample, or None before the first."""
        t = _Telemetry()
        code = _lib.mccs_telemetry(self._handle(), ctypes.byref(t))
        if code == ERR_NO_DATA:
            return None
        _check(code)
        return Telemetry(t.seq, t.tick, t.received_s, tuple(t.probe_mm), tuple(t.force_n), t.gain, t.flags, tuple(t.duties), tuple(t.proxy_mm))

    def watch_mesh(self, every: int) -> None:
        """A mesh every ``every`` ticks (0: none)."""
        _check(_lib.mccs_watch_mesh(self._handle(), _period("every", every)))

    def mesh(self) -> Optional[Tuple[int, List[MeshNode]]]:
        """The latest whole mesh as ``(seq, nodes)``, or None before the first."""
        count, seq = ctypes.c_size_t(), ctypes.c_uint32()
        code = _lib.mccs_mesh(self._handle(), None, 0, ctypes.byref(count), ctypes.byref(seq))
        if code == ERR_NO_DATA:
            return None
        if code not in (OK, ERR_BUFFER):
            _check(code)
        nodes = (_MeshNode * max(count.value, 1))()
        _check(_lib.mccs_mesh(self._handle(), nodes, count.value, ctypes.byref(count), ctypes.byref(seq)))
        return seq.value, [MeshNode(n.i, n.j, tuple(n.position_mm)) for n in nodes[: count.value]]

    def black_box(self) -> BlackBox:
        """The device's record of its last run, read whole (the board's 500 ticks take
        some 125 requests: about 2 s over a 115,200-baud link)."""
        head, count = _BlackBox(), ctypes.c_size_t()
        ticks = (_BoxTick * 512)()
        code = _lib.mccs_black_box(self._handle(), ctypes.byref(head), ticks, len(ticks), ctypes.byref(count))
        if code == ERR_BUFFER:
            ticks = (_BoxTick * count.value)()
            code = _lib.mccs_black_box(self._handle(), ctypes.byref(head), ticks, count.value, ctypes.byref(count))
        _check(code)
        return BlackBox(
            kept=bool(head.kept),
            stopped_by=_cause(head.stopped_by),
            part=head.part,
            stop_tick=head.stop_tick,
            ended_by=_cause(head.ended_by),
            end_tick=head.end_tick,
            pc=head.pc,
            reset_flags=head.reset_flags,
            ticks=[
                BoxTick(t.tick, tuple(t.counts), tuple(t.force_n), tuple(t.duties), t.gain, t.flags)
                for t in ticks[: count.value]
            ],
        )
