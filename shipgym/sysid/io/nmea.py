"""NMEA 0183 logs of a ship's own sensors read into a canonical record.

:func:`load_nmea` reads a text log of NMEA 0183 sentences (one a line, optionally after a
logger's time stamp or an NMEA 4.10 tag block), parses the sentences with ``pynmeagps``, puts a
time on every sentence, interpolates the channels onto one uniform time grid and hands the grid
to :meth:`Record.from_arrays`. :func:`shipgym.sysid.nmea_writer.write_nmea` writes a synthetic
log from simulated SI channels (tests and examples); :func:`looks_like_nmea` recognises a log
from its first lines.

Sentences read
--------------
Any talker (``HE``, ``HC``, ``GP``, ``GN``, ``II``, ``AG``, ...; one pynmeagps does not know is
parsed as ``II``):

=================== ============================================================================
channel             sentences and conversion
=================== ============================================================================
heading ``psi``     ``HDT`` true heading [deg]; ``THS`` true heading [deg] with mode A
                    (autonomous) or E (estimated), other modes (V invalid, M manual, S
                    simulator) dropped; ``HDG`` magnetic sensor heading [deg]: true = magnetic +
                    deviation + variation (E positive, W negative; a missing deviation is 0; a
                    missing variation is taken from the RMC magnetic variation, else the heading
                    stays magnetic and a note says so). HDT/THS are preferred over HDG.
                    deg -> rad, unwrapped.
rate of turn ``r``  ``ROT`` [deg/min], status A only; NMEA: negative = bow turns to port, so the
                    sign is the project's (positive clockwise); deg/min -> rad/s.
rudder ``delta``    ``RSA`` starboard (or single) rudder sensor [deg], status A only. NMEA defines
                    it as a relative measurement of the rudder angle with negative = bow turns
                    to port, i.e. starboard positive: the project's convention (positive rudder,
                    r > 0), so only deg -> rad, no sign change. The port sensor is not used.
speed ``U``         speed over ground: ``RMC`` [kn] (status A) or ``VTG`` [kn], or [km/h] when
                    only that field is given (mode N dropped) -> m/s.
``u``, ``v``        from the speed and course over ground of the same sentence and the heading:
                    ``u = U cos(COG - psi)``, ``v = U sin(COG - psi)`` (ground-referenced).
position ``x, y``   ``GGA`` (fix quality > 0), ``RMC`` (status A) or ``GLL`` (status A) latitude
                    and longitude [deg] -> north, east [m] from the first grid point (WGS84 local
                    tangent plane, :meth:`Record.from_arrays`).
=================== ============================================================================

When several sources give one channel (two gyros ``HEHDT`` and ``HCHDT``, RMC and VTG speed, ...)
the one with the most valid sentences is used (ties: the first listed above) and the others are
named in ``meta["conversions"]``; sources are never mixed.

Time
----
Logger time stamps: a line may start with a logger's time stamp, ``2026-12-31T23:59:58.100Z``
(ISO 8601; without a zone it is taken as UTC), ``[2026-12-31 23:59:58.100]``, a Unix time in
seconds (``1735689598.1``, or milliseconds for 13 digits), or an NMEA 4.10 tag block
``\\c:1735689598*hh\\`` (Unix seconds, or milliseconds above 1e11). When at least half of the
sentences carry one (or no sentence has a time of its own), the logger time is used for every
line (the sentences' own times are only compared with it, in ``meta["notes"]``).

Otherwise the sentence times are used: ``hhmmss.ss`` of ``RMC``, ``GGA``, ``GLL`` and ``ZDA``
(the time-stamped sentences). Each is placed on the day that puts it nearest to the previous
time-stamped sentence, so a log crossing midnight rolls over (23:59:59 -> 00:00:00 is +1 s), and
the date of the first day is solved afterwards from every ``ZDA`` and ``RMC`` date (a date
sentence arriving after midnight is fine). Without a date sentence the record keeps seconds of
the day and says so.

Sentences without a time of their own (``HDT``, ``THS``, ``HDG``, ``ROT``, ``RSA``, ``VTG``, and
lines without a logger stamp) are timed by one rule: the time stamps split the log into
intervals, each from one time stamp to the next larger one; within an interval the ``m``
sentences of one source (e.g. ``HEHDT``) get the times ``t_a + j (t_b - t_a) / m``,
``j = 0 .. m - 1``. That is exact for a sensor sending at a constant rate when the time-stamped
sentence of an instant is logged before the other sentences of that instant (as a GNSS receiver
starts its burst on the second); otherwise the error is at most one sample interval of that
source. After the last time stamp (and before the first) the source's median spacing continues
the sequence. The same rule spreads lines that share a coarse logger stamp (a whole-second tag
block) over that second. A sentence dropped for a bad checksum or an unreadable field keeps its
place in this count (it was sent at that point of the stream), so it does not shift the others.
A time stamp earlier than the one before it is not used as a stamp (counted in the notes).

Uniform grid and segments
-------------------------
The grid step ``dt`` is the median interval of the heading source (rounded to 1 us) unless
given; the grid runs ``t_k = t_0 + k dt`` over the heading's time span, and the record's time is
``t_k - t_0`` of the kept points (``meta["start_time"]``: the UTC time of the first one). Every
channel is interpolated linearly onto it (heading, course and longitude unwrapped first) only
where the two samples of that channel around ``t_k`` are at most ``max_gap_s`` apart (default,
per channel: the larger of 2 s and 5 times its median interval), so no gap longer than
``max_gap_s`` is bridged. Grid points where the heading (and the rudder, when the log has rudder
sentences) cannot be interpolated are dropped, which splits the record into segments at those
gaps; ``Record.from_arrays`` receives ``max_gap_s = 1.5 dt`` and lists them in
``meta["segments"]``.

An optional channel (rate of turn, speed, ``u``/``v``, position) is kept only if it covers every
kept grid point, except at the two ends of a segment: there up to its own ``max_gap_s`` of grid
points without it are trimmed (a 1 Hz fix ends up to 1 s before the 10 Hz heading). Otherwise it
is dropped with a note giving its coverage; without the rate of turn, ``r`` is derived from the
heading by :meth:`Record.from_arrays`. A log without rudder sentences is read with
``delta = 0`` and a :class:`~shipgym.sysid.ingest.SysidDataWarning` and note saying there is no
rudder sensor, so a model cannot be identified from it until the rudder is added.

Checks and repairs
------------------
A sentence with a wrong checksum (or a tag block with a wrong checksum) is dropped and counted:
``meta["repairs"]`` lists the lines and a :class:`~shipgym.sysid.ingest.SysidDataWarning` is
raised. Lines that are not NMEA sentences, sentences of a read type with an unreadable field and
malformed checksum fields are dropped and reported the same way; nothing unreadable is used.
Sentences without a checksum are kept (unverified) and counted in ``meta["notes"]``, as are
sentences marked invalid by their status field and sentence types that are not read (``GSV``,
AIS ``!AIVDM``, ...). A log without a heading sentence, or without any time, is refused with a
one-line ``ValueError``.
"""

from __future__ import annotations

import datetime
import math
import re
import warnings
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pynmeagps
from pynmeagps import NMEAReader, calc_checksum

from shipgym.sysid.ingest import SysidDataWarning, silent
from shipgym.sysid.io.registry import SourceFormat
from shipgym.sysid.record import Record
from shipgym.sysid.units import KNOT

__all__ = ["FORMAT", "NMEA_LOGGER_STYLES", "load_nmea", "looks_like_nmea"]

NMEA_LOGGER_STYLES: tuple[str, ...] = ("iso", "bracket", "epoch", "tag")
"""Logger time-stamp styles that :func:`load_nmea` reads (and
:func:`shipgym.sysid.nmea_writer.write_nmea` writes)."""

_KMH = 1.0 / 3.6  # m/s per km/h
_DAY = 86400.0
_READ = ("HDT", "THS", "HDG", "ROT", "RSA", "RMC", "GGA", "GLL", "VTG", "ZDA")
_TIMED = frozenset({"RMC", "GGA", "GLL", "ZDA"})
_STYLE_NAMES = {
    "iso": "ISO 8601",
    "bracket": "bracketed ISO 8601",
    "epoch": "Unix time",
    "tag": "tag block c:",
}
_MAX_LISTED_LINES = 10
_PROGRESS_LINES = 200_000

# a sentence: $ or ! then the address field (talker + type, or P + proprietary type)
_SENTENCE = re.compile(r"[$!][A-Z0-9]{4,6}[,*]")
_ISO_STAMP = re.compile(
    r"\[?\s*(\d{4}-\d{2}-\d{2}[T ]\d{2}:\d{2}:\d{2})([.,]\d+)?\s*(Z|[+-]\d{2}:?\d{2})?\s*\]?"
)
_EPOCH_STAMP = re.compile(r"\[?\s*(\d{9,13}(?:\.\d+)?)\s*\]?")
_TAG_BLOCK = re.compile(r"\\([^\\]*)\\$")
_HEAD_PREFIX = re.compile(
    r"(?:\[?\s*\d{4}-\d{2}-\d{2}[T ][0-9:.,]+\s*(?:Z|[+-]\d{2}:?\d{2})?\s*\]?"  # ISO 8601
    r"|\[?\d{9,13}(?:\.\d+)?\]?)?"  # Unix time
    r"[\s,;|]*(?:\\[^\\]*\\)?[$!][A-Z0-9]{4,6},"
)


# ----------------------------------------------------------------------------------------------
# recognising a log
# ----------------------------------------------------------------------------------------------
def looks_like_nmea(head: str) -> bool:
    """Whether the start of a file is an NMEA 0183 log.

    Parameters
    ----------
    head : str
        The first few kB of the file as text (a last line cut off mid-way is ignored).

    Returns
    -------
    bool
        True when at least three quarters of the first eight non-empty, non-comment (``#``)
        lines are NMEA sentences (``$`` or ``!`` and an address field), each possibly after a
        logger time stamp (ISO 8601, bracketed, Unix seconds) or a tag block: a logger's banner
        line before the sentences is allowed (the reader drops and counts it).
    """
    lines = head.removeprefix("\ufeff").splitlines()
    if len(lines) > 1 and not head.endswith(("\n", "\r")):
        lines = lines[:-1]  # cut off by the caller's read size
    lines = [ln.strip() for ln in lines if ln.strip() and not ln.lstrip().startswith("#")][:8]
    if not lines:
        return False
    hits = [_HEAD_PREFIX.match(ln) is not None for ln in lines]
    return sum(hits) >= 0.75 * len(hits)


# ----------------------------------------------------------------------------------------------
# scanning the lines
# ----------------------------------------------------------------------------------------------
@dataclass
class _Scan:
    """The sentences of a log that are read, in file order, plus the counts of the rest."""

    n_lines: int = 0
    n_sentences: int = 0
    counts: Counter[str] = field(default_factory=Counter)  # every sentence type seen
    line: list[int] = field(default_factory=list)  # 1-based line number
    source: list[str] = field(default_factory=list)  # address, e.g. "HEHDT"
    msgid: list[str] = field(default_factory=list)  # e.g. "HDT"
    stamp: list[float] = field(default_factory=list)  # logger time [s since 1970, UTC] or nan
    tod: list[float] = field(default_factory=list)  # sentence time of day [s] or nan
    date: list[datetime.date | None] = field(default_factory=list)
    values: list[tuple[float, ...] | None] = field(default_factory=list)  # None: placeholder
    bad_checksum: list[int] = field(default_factory=list)
    unparseable: list[int] = field(default_factory=list)
    no_checksum: int = 0
    invalid: Counter[str] = field(default_factory=Counter)  # source -> sentences marked invalid
    stamp_styles: Counter[str] = field(default_factory=Counter)
    naive_stamps: int = 0
    unknown_prefix: list[int] = field(default_factory=list)
    comments: int = 0
    port_rudder: int = 0

    def add(
        self,
        line: int,
        source: str,
        msgid: str,
        stamp: float,
        tod: float = math.nan,
        date: datetime.date | None = None,
        values: tuple[float, ...] | None = None,
    ) -> None:
        self.line.append(line)
        self.source.append(source)
        self.msgid.append(msgid)
        self.stamp.append(stamp)
        self.tod.append(tod)
        self.date.append(date)
        self.values.append(values)


def _num(value: Any) -> float:
    """A parsed numeric field as float, nan when empty or not a number."""
    if isinstance(value, int | float) and not isinstance(value, bool):
        return float(value)
    return math.nan


def _signed(value: Any, hemisphere: Any) -> float:
    """A magnitude with an E/W letter as a signed number (E positive); nan when incomplete."""
    v = _num(value)
    if hemisphere == "E":
        return v
    if hemisphere == "W":
        return -v
    return math.nan


def _time_of_day(value: Any) -> float:
    if isinstance(value, datetime.time):
        return value.hour * 3600.0 + value.minute * 60.0 + value.second + value.microsecond * 1e-6
    return math.nan


def _parse_stamp(prefix: str, scan: _Scan) -> tuple[float, str | None, bool]:
    """Logger time stamp in ``prefix`` -> (Unix time or nan, style, tag checksum ok)."""
    text = prefix.strip()
    stamp, style = math.nan, None
    tag = _TAG_BLOCK.search(text)
    if tag is not None:
        body, star, given = tag.group(1).partition("*")
        if star and given.upper() != calc_checksum(body):
            return math.nan, "tag", False
        for item in body.split(","):
            key, _, value = item.partition(":")
            if key == "c" and re.fullmatch(r"\d+(?:\.\d+)?", value):
                stamp, style = float(value), "tag"
                if stamp > 1e11:
                    stamp *= 1e-3
        text = text[: tag.start()].strip()
    text = text.rstrip(" \t,;|")
    if not text:
        return stamp, style, True
    m = _ISO_STAMP.fullmatch(text)
    if m is not None:
        frac = (m.group(2) or "").replace(",", ".")[:7]
        zone = m.group(3)
        try:
            when = datetime.datetime.fromisoformat(m.group(1).replace(" ", "T") + frac)
        except ValueError:
            return stamp, style, True
        if zone is None:
            scan.naive_stamps += 1
            when = when.replace(tzinfo=datetime.UTC)
        else:
            zone = "+00:00" if zone == "Z" else zone
            if ":" not in zone:
                zone = zone[:3] + ":" + zone[3:]
            when = datetime.datetime.fromisoformat(when.isoformat() + zone)
        return when.timestamp(), "bracket" if text.startswith("[") else "iso", True
    m = _EPOCH_STAMP.fullmatch(text)
    if m is not None:
        value = float(m.group(1))
        return (value * 1e-3 if value > 1e11 else value), "epoch", True
    return stamp, "unknown", True


def _values(msgid: str, msg: Any, scan: _Scan) -> tuple[float, ...] | None:
    """The numbers used from one parsed sentence; None when marked invalid."""
    get = msg.__dict__.get
    if msgid == "HDT":
        return (_num(get("headingT")),)
    if msgid == "THS":
        return (_num(get("headt")),) if get("mi") in ("A", "E") else None
    if msgid == "HDG":
        return (
            _num(get("headingM")),
            _signed(get("deviation"), get("deviationEW")),
            _signed(get("variation"), get("variationEW")),
        )
    if msgid == "ROT":
        return (_num(get("rot")),) if get("valid") == "A" else None
    if msgid == "RSA":
        if get("portstatus") == "A" and math.isfinite(_num(get("portangle"))):
            scan.port_rudder += 1
        return (_num(get("stbdangle")),) if get("stbdstatus") == "A" else None
    if msgid == "RMC":
        if get("status") != "A" or get("posMode") == "N":
            return None
        return (
            _num(get("lat")),
            _num(get("lon")),
            _num(get("spd")) * KNOT,
            _num(get("cog")),
            _signed(get("mv"), get("mvEW")),
        )
    if msgid == "GGA":
        return (_num(get("lat")), _num(get("lon"))) if _num(get("quality")) > 0 else None
    if msgid == "GLL":
        if get("status") != "A" or get("posMode") == "N":
            return None
        return (_num(get("lat")), _num(get("lon")))
    if msgid == "VTG":
        if get("posMode") == "N":
            return None
        sog = _num(get("sogn")) * KNOT if get("sognUnit") == "N" else math.nan
        if not math.isfinite(sog) and get("sogkUnit") == "K":
            sog = _num(get("sogk")) * _KMH
        cog = _num(get("cogt")) if get("cogtUnit") == "T" else math.nan
        return (sog, cog)
    return ()  # ZDA: time and date only


def _date_of(msgid: str, msg: Any) -> datetime.date | None:
    get = msg.__dict__.get
    if msgid == "RMC" and isinstance(get("date"), datetime.date):
        return get("date")
    if msgid == "ZDA":
        try:
            return datetime.date(int(get("year")), int(get("month")), int(get("day")))
        except (TypeError, ValueError):
            return None
    return None


def _scan(path: Path, say: Callable[[str], None]) -> _Scan:
    """Read every line of the log: checksums, logger stamps, parsed values."""
    scan = _Scan()
    talkers = pynmeagps.NMEA_TALKERS
    with path.open("r", encoding="utf-8-sig", errors="replace", newline=None) as fh:
        for number, raw in enumerate(fh, start=1):
            scan.n_lines = number
            if number % _PROGRESS_LINES == 0:
                say(f"{path.name}: {number:,} lines read")
            line = raw.strip()
            if not line:
                continue
            m = _SENTENCE.search(line)
            if m is None:
                if line.startswith("#"):
                    scan.comments += 1
                else:
                    scan.unparseable.append(number)
                continue
            scan.n_sentences += 1
            sentence = line[m.start() :]
            address = line[m.start() + 1 : m.end() - 1]
            msgid = address if address.startswith("P") else address[2:]
            talker = "P" if address.startswith("P") else address[:2]
            scan.counts[msgid] += 1
            body, star, given = sentence.partition("*")
            stamp, style, tag_ok = _parse_stamp(line[: m.start()], scan)
            if style == "unknown":
                scan.unknown_prefix.append(number)
            elif style is not None:
                scan.stamp_styles[style] += 1
            read = msgid in _READ and sentence[0] == "$"
            if star and not re.fullmatch(r"[0-9A-Fa-f]{2}", given):
                scan.unparseable.append(number)
                if read:
                    scan.add(number, address, msgid, stamp)
                continue
            checksum = calc_checksum(body[1:])
            if not tag_ok or (star and given.upper() != checksum):
                scan.bad_checksum.append(number)
                if read:  # keeps its place in the timing of its source (module docstring)
                    scan.add(number, address, msgid, stamp)
                continue
            if not star:
                scan.no_checksum += 1
            if not read:
                continue
            if talker not in talkers:  # pynmeagps knows the registered talkers only
                body = "$II" + body[3:]
                checksum = calc_checksum(body[1:])
            try:
                # the checksum is verified above (or absent): parse checks the message type
                msg = NMEAReader.parse(f"{body}*{checksum}", validate=pynmeagps.VALMSGID)
            except (
                pynmeagps.NMEAParseError,
                pynmeagps.NMEAMessageError,
                pynmeagps.NMEATypeError,
                ValueError,
                TypeError,
                IndexError,
            ):
                msg = None
            if msg is None:
                scan.unparseable.append(number)
                scan.add(number, address, msgid, stamp)
                continue
            values = _values(msgid, msg, scan)
            if values is None:
                scan.invalid[address] += 1
                scan.add(number, address, msgid, stamp)
                continue
            tod = _time_of_day(msg.__dict__.get("time")) if msgid in _TIMED else math.nan
            scan.add(number, address, msgid, stamp, tod, _date_of(msgid, msg), values)
    return scan


# ----------------------------------------------------------------------------------------------
# times
# ----------------------------------------------------------------------------------------------
def _lines_text(lines: Sequence[int]) -> str:
    shown = ", ".join(str(n) for n in lines[:_MAX_LISTED_LINES])
    more = len(lines) - _MAX_LISTED_LINES
    return f"{shown} and {more} more" if more > 0 else shown


def _counts_text(counts: Mapping[str, int]) -> str:
    if not counts:
        return "none"
    return ", ".join(f"{k} {v}" for k, v in sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])))


def _found_text(scan: _Scan) -> str:
    """The sentences of a log by type, and those of them dropped as unusable (for errors)."""
    dropped = []
    if scan.bad_checksum:
        dropped.append(f"{len(scan.bad_checksum)} for a bad checksum")
    if scan.unparseable:
        dropped.append(f"{len(scan.unparseable)} unreadable")
    text = _counts_text(scan.counts)
    return f"{text} (of them dropped: {', '.join(dropped)})" if dropped else text


def _spread(
    anchor: np.ndarray, own: np.ndarray, source_code: np.ndarray
) -> tuple[np.ndarray, int, np.ndarray]:
    """Times of all entries by the interval rule of the module docstring.

    Returns the times (nan where none can be given), the number of stamps not used because
    they go backwards, and the stamp (group) times.
    """
    n = anchor.size
    group = np.empty(n, dtype=np.int64)
    starts: list[float] = []
    current, g, backwards = -math.inf, -1, 0
    for i, a in enumerate(anchor.tolist()):
        if a == a:  # not nan
            if a > current:
                g += 1
                starts.append(a)
                current = a
            elif a < current:
                backwards += 1
        group[i] = g
    times = own.copy()
    stamps = np.asarray(starts)
    if stamps.size == 0:
        return times, backwards, stamps
    n_groups = stamps.size
    length = np.diff(stamps)
    spread = ~np.isfinite(own)
    for code in np.unique(source_code[spread]):
        idx = np.flatnonzero(spread & (source_code == code))
        gg = group[idx]
        first = np.concatenate(([True], gg[1:] != gg[:-1]))
        run_start = np.flatnonzero(first)
        run_len = np.diff(np.append(run_start, gg.size))
        j = np.arange(gg.size) - np.repeat(run_start, run_len)
        m = np.repeat(run_len, run_len)
        t = np.full(gg.size, math.nan)
        inner = (gg >= 0) & (gg < n_groups - 1)
        t[inner] = stamps[gg[inner]] + length[gg[inner]] * j[inner] / m[inner]
        full_runs = (gg[run_start] >= 0) & (gg[run_start] < n_groups - 1)
        if np.any(full_runs):
            spacing = float(np.median(length[gg[run_start][full_runs]] / run_len[full_runs]))
            last = gg == n_groups - 1
            t[last] = stamps[-1] + j[last] * spacing
            before = gg < 0
            t[before] = stamps[0] - (m[before] - j[before]) * spacing
        times[idx] = t
    return times, backwards, stamps


@dataclass
class _Timing:
    """Time of every read sentence [s from ``origin``] and what it was built from."""

    t: np.ndarray
    origin: datetime.datetime | None  # UTC time of t = 0, None when the date is unknown
    conversions: list[str]
    notes: list[str]


def _timing(scan: _Scan, name: str) -> _Timing:
    n = len(scan.line)
    stamp = np.asarray(scan.stamp, dtype=np.float64)
    tod = np.asarray(scan.tod, dtype=np.float64)
    codes = {s: k for k, s in enumerate(dict.fromkeys(scan.source))}
    source_code = np.fromiter((codes[s] for s in scan.source), dtype=np.int64, count=n)
    has_stamp = np.isfinite(stamp)
    conversions: list[str] = []
    notes: list[str] = []
    n_timed = int(np.isfinite(tod).sum())
    if has_stamp.any() and (has_stamp.sum() >= 0.5 * n or n_timed == 0):
        base = math.floor(float(stamp[has_stamp][0]))
        anchor = stamp - base
        times, backwards, stamps = _spread(anchor, np.full(n, math.nan), source_code)
        origin = datetime.datetime.fromtimestamp(base, tz=datetime.UTC)
        styles = ", ".join(_STYLE_NAMES[k] for k in sorted(scan.stamp_styles))
        conversions.append(
            f"time: the logger's time stamps ({styles}, UTC) on every line; lines sharing a stamp "
            "and lines without one spread per sentence source between stamps"
        )
        if scan.naive_stamps:
            notes.append(f"{scan.naive_stamps} logger time stamps have no time zone: taken as UTC")
        if n_timed:
            own = np.isfinite(tod) & has_stamp
            offset = np.mod(anchor[own] + base - tod[own] + _DAY / 2, _DAY) - _DAY / 2
            notes.append(
                f"logger clock minus the sentence (GNSS) time: median {np.median(offset):+.3f} s "
                f"over {int(own.sum())} time-stamped sentences (the logger time is used)"
            )
        if not has_stamp.all():
            notes.append(
                f"{int((~has_stamp).sum())} read sentences have no logger time stamp: spread "
                "between the stamps"
            )
    else:
        if n_timed == 0:
            raise ValueError(
                f"{name}: no time in {scan.n_sentences} sentences: no logger time stamps and no "
                f"usable time-stamped sentence (RMC, GGA, GLL, ZDA); found {_found_text(scan)}; "
                "expected one of them"
            )
        absolute = np.full(n, math.nan)
        prev: float | None = None
        rollovers = 0
        for i in np.flatnonzero(np.isfinite(tod)).tolist():
            v = float(tod[i])
            if prev is None:
                a = v
            else:
                a = v + _DAY * round((prev - v) / _DAY)
                if math.floor(a / _DAY) > math.floor(prev / _DAY):
                    rollovers += 1
            absolute[i] = a
            prev = a
        times, backwards, stamps = _spread(absolute, absolute, source_code)
        dates: Counter[datetime.date] = Counter()
        for i in np.flatnonzero(np.isfinite(absolute)).tolist():
            d = scan.date[i]
            if d is not None:
                dates[d - datetime.timedelta(days=math.floor(absolute[i] / _DAY))] += 1
        midnight = (
            f"; {rollovers} midnight roll-over{'s' if rollovers != 1 else ''}" if rollovers else ""
        )
        conversions.append(
            "time: the sentence times (hhmmss.ss of RMC, GGA, GLL, ZDA), each on the day nearest "
            f"the previous one{midnight}; sentences without a time (HDT, THS, HDG, ROT, RSA, "
            "VTG) spread uniformly per sentence source between consecutive time stamps"
        )
        if dates:
            day0, count = dates.most_common(1)[0]
            origin = datetime.datetime.combine(day0, datetime.time(), tzinfo=datetime.UTC)
            conversions.append(f"date from the ZDA/RMC sentences: {day0.isoformat()} (UTC)")
            if len(dates) > 1:
                notes.append(
                    f"the date sentences disagree: {count} give {day0.isoformat()}, "
                    f"{sum(dates.values()) - count} another date; the most common is used"
                )
        else:
            origin = None
            notes.append(
                "no date sentence (ZDA, RMC): times are seconds of the day of the first "
                "time-stamped sentence, the date is unknown"
            )
        if stamps.size > 2:
            longest = float(np.max(np.diff(stamps)))
            typical = float(np.median(np.diff(stamps)))
            if longest > max(5.0, 5.0 * typical):
                notes.append(
                    f"the longest interval between time-stamped sentences is {longest:g} s "
                    f"(typical {typical:g} s): sentences inside it are spread uniformly over it"
                )
        if has_stamp.any():
            notes.append(
                f"only {int(has_stamp.sum())} of {n} read sentences carry a logger time stamp: "
                "the sentence times are used"
            )
    if backwards:
        notes.append(f"{backwards} time stamps earlier than the one before them were not used")
    lost = sum(scan.values[i] is not None for i in np.flatnonzero(~np.isfinite(times)).tolist())
    if lost:
        notes.append(
            f"{lost} sentences could not be timed (before the first or after the last time "
            "stamp of a source without a regular spacing): not used"
        )
    return _Timing(times, origin, conversions, notes)


# ----------------------------------------------------------------------------------------------
# channels
# ----------------------------------------------------------------------------------------------
@dataclass
class _Series:
    """One channel as read: sample times [s] and values (in the sentence's unit), sorted by
    time, without repeated times."""

    source: str
    t: np.ndarray
    v: np.ndarray
    dt: float = field(init=False)

    def __post_init__(self) -> None:
        self.dt = float(np.median(np.diff(self.t))) if self.t.size > 1 else math.nan


def _column(scan: _Scan, idx: np.ndarray, k: int) -> np.ndarray:
    vals = scan.values
    return np.fromiter(
        (vals[i][k] if vals[i] is not None else math.nan for i in idx.tolist()),
        dtype=np.float64,
        count=idx.size,
    )


def _series(
    source: str, t: np.ndarray, v: np.ndarray, angle: bool, notes: list[str]
) -> _Series | None:
    ok = np.isfinite(t) & np.isfinite(v)
    t, v = t[ok], v[ok]
    order = np.argsort(t, kind="stable")
    t, v = t[order], v[order]
    keep = np.concatenate(([True], np.diff(t) > 0.0)) if t.size else np.zeros(0, dtype=bool)
    if t.size and not keep.all():
        notes.append(f"{source}: {int((~keep).sum())} samples with a repeated time dropped")
        t, v = t[keep], v[keep]
    if t.size < 2:
        return None
    if angle:
        v = np.unwrap(v, period=360.0)
    return _Series(source, t, v)


class _Channels:
    """Sources per sentence type and the selection of one source per channel."""

    def __init__(self, scan: _Scan, times: np.ndarray) -> None:
        self.scan = scan
        self.times = times
        self.by_source: dict[str, np.ndarray] = {}
        src = np.asarray(scan.source, dtype=object)
        for s in dict.fromkeys(scan.source):
            self.by_source[s] = np.flatnonzero(src == s)
        self.msgid = dict(zip(scan.source, scan.msgid, strict=True))

    def valid_count(self, source: str, k: int = 0) -> int:
        col = _column(self.scan, self.by_source[source], k)
        return int(np.sum(np.isfinite(col) & np.isfinite(self.times[self.by_source[source]])))

    def candidates(self, columns: Mapping[str, int]) -> list[tuple[str, int]]:
        """Sources of the types ``columns`` (type -> value column) with their valid-sample
        counts, best first (ties: the order of ``columns``)."""
        rank = list(columns)
        found = [
            (s, self.valid_count(s, columns[m]), rank.index(m))
            for s, m in self.msgid.items()
            if m in columns
        ]
        found = [f for f in found if f[1] > 0]
        found.sort(key=lambda f: (-f[1], f[2], f[0]))
        return [(s, c) for s, c, _ in found]

    def column(self, source: str, k: int) -> tuple[np.ndarray, np.ndarray]:
        idx = self.by_source[source]
        return self.times[idx], _column(self.scan, idx, k)


def _others(chosen: str, candidates: Sequence[tuple[str, int]]) -> str:
    rest = [f"{s} ({c})" for s, c in candidates if s != chosen]
    return f"; not used: {', '.join(rest)}" if rest else ""


# ----------------------------------------------------------------------------------------------
# grid
# ----------------------------------------------------------------------------------------------


def _positive(value: float | None, what: str) -> float | None:
    if value is None:
        return None
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0.0):
        raise ValueError(f"{what} must be a positive finite number of seconds, got {value!r}")
    return float(value)


def _plural(k: int, word: str) -> str:
    return f"{k} {word}{'s' if k != 1 else ''}"


def _scan_meta(scan: _Scan, name: str) -> dict[str, Any]:
    """The record's meta from the scan: repairs (with warnings) and notes."""
    meta: dict[str, Any] = {
        "source": "nmea",
        "file": name,
        "conversions": [],
        "repairs": [],
        "notes": [],
        "sentence_counts": dict(sorted(scan.counts.items())),
    }
    repairs: list[str] = []
    if scan.bad_checksum:
        k = len(scan.bad_checksum)
        repairs.append(
            f"dropped {_plural(k, 'sentence')} with a bad checksum "
            f"(line{'s' if k != 1 else ''} {_lines_text(scan.bad_checksum)})"
        )
    if scan.unparseable:
        k = len(scan.unparseable)
        repairs.append(
            f"dropped {_plural(k, 'unreadable line')} (not an NMEA sentence, a malformed "
            f"checksum or a field that does not parse; line{'s' if k != 1 else ''} "
            f"{_lines_text(scan.unparseable)})"
        )
    for message in repairs:
        meta["repairs"].append(message)
        warnings.warn(f"{name}: {message}", SysidDataWarning, stacklevel=3)
    notes: list[str] = meta["notes"]
    if scan.no_checksum:
        notes.append(
            f"{_plural(scan.no_checksum, 'sentence')} without a checksum: kept, unverified"
        )
    if scan.comments:
        notes.append(f"{_plural(scan.comments, 'comment line')} (#) skipped")
    if scan.unknown_prefix:
        notes.append(
            f"{_plural(len(scan.unknown_prefix), 'line')} start with text that is not a logger "
            f"time stamp (ignored; lines {_lines_text(scan.unknown_prefix)})"
        )
    for source, k in sorted(scan.invalid.items()):
        notes.append(f"{k} {source} marked invalid by their status field: not used")
    ignored = {m: c for m, c in scan.counts.items() if m not in _READ}
    if ignored:
        notes.append(f"sentence types not read: {_counts_text(ignored)}")
    return meta


def _heading(chans: _Channels, scan: _Scan, name: str, meta: dict[str, Any]) -> _Series:
    """The heading [deg, true, unwrapped] from the best source (module docstring)."""
    notes: list[str] = meta["notes"]
    true_src = chans.candidates({"HDT": 0, "THS": 0})
    mag_src = chans.candidates({"HDG": 0})
    if true_src:
        src = true_src[0][0]
        t, h_deg = chans.column(src, 0)
        hdg = f"; HDG not used ({', '.join(s for s, _ in mag_src)})" if mag_src else ""
        meta["conversions"].append(
            f"heading: {src} true heading [deg] -> psi [rad], unwrapped"
            f"{_others(src, true_src)}{hdg}"
        )
    elif mag_src:
        src = mag_src[0][0]
        t, mag = chans.column(src, 0)
        dev, var = chans.column(src, 1)[1], chans.column(src, 2)[1]
        no_dev, no_var = np.isfinite(mag) & np.isnan(dev), np.isfinite(mag) & np.isnan(var)
        if no_dev.any():
            notes.append(f"{src}: {int(no_dev.sum())} without a deviation: 0 used")
        if no_var.any():
            rmc = chans.candidates({"RMC": 4})
            fill = float(np.nanmedian(chans.column(rmc[0][0], 4)[1])) if rmc else 0.0
            notes.append(
                f"{src}: {int(no_var.sum())} without a variation: "
                + (
                    f"{fill:+g} deg from the {rmc[0][0]} magnetic variation"
                    if rmc
                    else "no RMC variation either, so that heading is magnetic, not true"
                )
            )
            var = np.where(np.isnan(var), fill, var)
        h_deg = mag + np.nan_to_num(dev, nan=0.0) + var
        meta["conversions"].append(
            f"heading: {src} magnetic heading + deviation + variation (E positive, W negative) "
            f"= true heading [deg] -> psi [rad], unwrapped{_others(src, mag_src)}"
        )
    else:
        raise ValueError(
            f"{name}: no valid heading in {scan.n_sentences} sentences (every HDT, THS and HDG "
            f"is marked invalid or cannot be timed); found {_found_text(scan)}; "
            "expected a heading to identify a model"
        )
    heading = _series(src, t, h_deg, True, notes)
    if heading is None:
        raise ValueError(f"{name}: fewer than 2 timed heading samples from {src}")
    return heading


class _Grid:
    """The uniform grid, the grid points kept so far and the channels interpolated onto it."""

    def __init__(self, heading: _Series, dt: float | None, max_gap_s: float | None) -> None:
        self.max_gap_s = max_gap_s
        step = dt if dt is not None else round(heading.dt, 6)
        if not step > 0.0:
            raise ValueError(f"the heading sentences of {heading.source} have no positive interval")
        self.step = step
        n = math.floor((heading.t[-1] - heading.t[0]) / step + 1e-9) + 1
        self.t = heading.t[0] + step * np.arange(n)
        self.psi_deg, self.kept = self.interpolate(heading)

    def gap(self, s: _Series) -> float:
        """Longest sample gap [s] of ``s`` that is interpolated over."""
        return self.max_gap_s if self.max_gap_s is not None else max(2.0, 5.0 * s.dt)

    def interpolate(self, s: _Series) -> tuple[np.ndarray, np.ndarray]:
        """Linear interpolation of ``s`` on the grid and where it is allowed (module docstring):
        an exact sample, or two samples around the grid time at most ``gap(s)`` apart."""
        n = s.t.size
        i = np.searchsorted(s.t, self.t, side="left")
        hi = np.minimum(i, n - 1)
        lo = np.maximum(i - 1, 0)
        exact = (i < n) & (s.t[hi] == self.t)
        ok = exact | ((i > 0) & (i < n) & (s.t[hi] - s.t[lo] <= self.gap(s)))
        return np.interp(self.t, s.t, s.v), ok

    def edge_trim(self, ok: np.ndarray, s: _Series) -> np.ndarray | None:
        """Grid points to drop so that ``ok`` covers every kept point, if they are only at
        segment ends (at most ``gap(s)`` at each end); None otherwise."""
        edge = math.floor(self.gap(s) / self.step + 1e-9)
        trim = np.zeros_like(self.kept)
        for a, b in _runs(self.kept):
            covered = np.flatnonzero(ok[a:b])
            if covered.size == 0:
                return None
            first, last = int(covered[0]), int(covered[-1])
            if first > edge or (b - a - 1 - last) > edge or not ok[a + first : a + last + 1].all():
                return None
            trim[a : a + first] = True
            trim[a + last + 1 : b] = True
        return trim


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges [a, b) of the runs of True."""
    edges = np.flatnonzero(np.diff(np.concatenate(([0], mask.astype(np.int8), [0]))))
    return list(zip(edges[0::2].tolist(), edges[1::2].tolist(), strict=True))


def _rudder(
    chans: _Channels, scan: _Scan, grid: _Grid, name: str, meta: dict[str, Any]
) -> np.ndarray | None:
    """Rudder [deg] on the grid (required where present: drops grid points), or None."""
    rsa = chans.candidates({"RSA": 0})
    rudder = _series(rsa[0][0], *chans.column(rsa[0][0], 0), False, meta["notes"]) if rsa else None
    if rudder is None:
        message = (
            "no rudder sensor (no valid RSA sentence): delta is 0, so a model cannot be "
            "identified from this record until a rudder angle is added"
        )
        meta["notes"].append(message)
        warnings.warn(f"{name}: {message}", SysidDataWarning, stacklevel=3)
        return None
    delta_deg, ok = grid.interpolate(rudder)
    grid.kept &= ok
    meta["conversions"].append(
        f"rudder: {rudder.source} starboard (or single) rudder sensor [deg; NMEA: negative = "
        "bow turns to port, i.e. starboard positive as here] -> delta [rad], no sign change"
        f"{_others(rudder.source, rsa)}"
    )
    if scan.port_rudder:
        meta["notes"].append(
            f"{_plural(scan.port_rudder, 'RSA sentence')} also give a port rudder angle: not used"
        )
    return delta_deg


def _optional(chans: _Channels, grid: _Grid, meta: dict[str, Any]) -> dict[str, np.ndarray]:
    """The optional channels on the grid (deg, m/s, deg/min as read), each kept only where it
    covers every kept grid point but for segment ends, which are trimmed (module docstring)."""
    notes: list[str] = meta["notes"]
    offered: dict[str, tuple[_Series, list[tuple[str, int]]]] = {}

    def offer(key: str, candidates: list[tuple[str, int]], k: int, angle: bool = False) -> None:
        if candidates:
            src = candidates[0][0]
            s = _series(src, *chans.column(src, k), angle, notes)
            if s is not None:
                offered[key] = (s, candidates)

    offer("r", chans.candidates({"ROT": 0}), 0)
    speed = chans.candidates({"RMC": 2, "VTG": 0})
    if speed:
        rmc = chans.msgid[speed[0][0]] == "RMC"
        offer("U", speed, 2 if rmc else 0)
        offer("course", speed, 3 if rmc else 1, angle=True)
    position = chans.candidates({"GGA": 0, "RMC": 0, "GLL": 0})
    if position:
        src = position[0][0]
        t, lat = chans.column(src, 0)
        lon = chans.column(src, 1)[1]
        both = np.isfinite(lat) & np.isfinite(lon)
        s_lat = _series(src, t[both], lat[both], False, notes)
        s_lon = _series(src, t[both], lon[both], True, notes)
        if s_lat is not None and s_lon is not None:
            offered["lat"], offered["lon"] = (s_lat, position), (s_lon, position)
    labels = {"r": "rate of turn", "U": "speed", "course": "course", "lat": "position"}
    out: dict[str, np.ndarray] = {}
    for key, (s, candidates) in offered.items():
        if (key == "course" and "U" not in out) or (key == "lon" and "lat" not in out):
            continue
        values, ok = grid.interpolate(s)
        trim = grid.edge_trim(ok, s)
        if trim is None:
            cover = float(np.mean(ok[grid.kept]))
            notes.append(
                f"{labels[key]} ({s.source}) covers {100 * cover:.1f} % of the kept grid points "
                "with gaps inside segments: not kept"
            )
            continue
        grid.kept &= ~trim
        out[key] = values
        others = _others(s.source, candidates)
        if key == "r":
            meta["conversions"].append(
                f"rate of turn: {s.source} [deg/min; NMEA: negative = bow turns to port] -> r "
                f"[rad/s]{others}"
            )
            meta["r_source"] = f"measured: {s.source} rate of turn"
        elif key == "U":
            unit = "kn" if chans.msgid[s.source] == "RMC" else "kn, or km/h without kn"
            meta["conversions"].append(
                f"speed: {s.source} speed over ground [{unit}] -> U [m/s]{others}"
            )
        elif key == "course":
            meta["conversions"].append(
                f"u, v = U (cos, sin)(COG - psi) with the {s.source} course over ground "
                "(ground-referenced)"
            )
        elif key == "lat":
            meta["conversions"].append(f"position: {s.source} latitude, longitude [deg]{others}")
    return out


def load_nmea(
    path: Path,
    say: Callable[[str], None] = silent,
    *,
    dt: float | None = None,
    max_gap_s: float | None = None,
) -> Record:
    """Read an NMEA 0183 log into a canonical :class:`~shipgym.sysid.record.Record`.

    The sentences, conversions, the timing of every sentence, the uniform grid, the segments and
    the repairs are described in the module docstring.

    Parameters
    ----------
    path : pathlib.Path
        The log: NMEA 0183 sentences, one a line, optionally after a logger time stamp or a tag
        block.
    say : callable, optional
        Receives one-line progress messages (every 200 000 lines and a summary).
    dt : float, optional
        Grid step [s]; the median interval of the heading sentences when None.
    max_gap_s : float, optional
        Longest gap [s] between two samples of a channel that is interpolated over, for every
        channel; when None, per channel the larger of 2 s and 5 times its median interval.

    Returns
    -------
    Record
        Time [s] from the first grid point (``meta["start_time"]``: its UTC time in ISO 8601
        when the date is known, else ``meta["start_time_of_day_s"]``), ``psi``, ``delta``,
        ``r`` (``ROT`` or derived from ``psi``) and, when present, ``U``, ``u``, ``v``, ``x``,
        ``y``. ``meta["segments"]`` lists the parts between gaps.

    Raises
    ------
    ValueError
        A file without NMEA sentences, without a heading sentence, without any time, or with
        fewer than two grid points; a non-positive ``dt`` or ``max_gap_s``.

    Warns
    -----
    SysidDataWarning
        Sentences dropped for a bad checksum or as unreadable (listed in ``meta["repairs"]``),
        and a log without rudder sentences.
    """
    path = Path(path)
    name = path.name
    dt = _positive(dt, "dt")
    max_gap_s = _positive(max_gap_s, "max_gap_s")
    if not path.is_file():
        raise ValueError(f"{path} is not a file")
    scan = _scan(path, say)
    if scan.n_sentences == 0:
        raise ValueError(
            f"{name}: no NMEA 0183 sentence ($ or ! lines) in {scan.n_lines} lines; expected an "
            "NMEA log"
        )
    meta = _scan_meta(scan, name)
    if not any(m in scan.counts for m in ("HDT", "THS", "HDG")):
        raise ValueError(
            f"{name}: no heading sentence (HDT, THS or HDG) in {scan.n_sentences} sentences; "
            f"found {_found_text(scan)}; expected a heading to identify a model"
        )
    timing = _timing(scan, name)
    meta["conversions"] += timing.conversions
    meta["notes"] += timing.notes
    chans = _Channels(scan, timing.t)
    heading = _heading(chans, scan, name, meta)
    grid = _Grid(heading, dt, max_gap_s)
    meta["conversions"].append(
        f"uniform grid: dt = {grid.step:g} s ("
        + ("given" if dt is not None else f"median {heading.source} interval")
        + "), linear interpolation, no channel interpolated across a sample gap longer than "
        + (f"{max_gap_s:g} s" if max_gap_s is not None else "max(2 s, 5 x its median interval)")
    )
    delta_deg = _rudder(chans, scan, grid, name, meta)
    if grid.kept.sum() < 2:
        raise ValueError(
            f"{name}: fewer than 2 grid points have both a heading and a rudder angle; expected "
            "heading and rudder sentences over the same time"
        )
    optional = _optional(chans, grid, meta)
    kept = grid.kept
    n_drop = int(kept.size - kept.sum())
    if n_drop:
        meta["notes"].append(
            f"{n_drop} of {kept.size} grid points dropped (no heading or rudder within the gap "
            f"limit, or a segment end without an optional channel): "
            f"{_plural(len(_runs(kept)), 'segment')}"
        )
    index = np.flatnonzero(kept)
    psi = np.radians(grid.psi_deg[index])
    arrays: dict[str, np.ndarray] = {
        "time": grid.step * (index - index[0]),  # exact multiples of the step
        "psi": psi,
        "delta": np.zeros(index.size) if delta_deg is None else np.radians(delta_deg[index]),
    }
    if "r" in optional:
        arrays["r"] = np.radians(optional["r"][index]) / 60.0
    if "U" in optional:
        arrays["U"] = optional["U"][index]
        if "course" in optional:
            drift = np.radians(optional["course"][index]) - psi
            arrays["u"], arrays["v"] = arrays["U"] * np.cos(drift), arrays["U"] * np.sin(drift)
    if "lat" in optional:
        arrays["lat"] = optional["lat"][index]
        lon = optional["lon"][index]  # continuous (unwrapped) across the antimeridian
        arrays["lon"] = lon - 360.0 * round(float(lon[0]) / 360.0)
    t0 = float(grid.t[index[0]])
    if timing.origin is not None:
        meta["start_time"] = (timing.origin + datetime.timedelta(seconds=t0)).isoformat()
    else:
        meta["start_time_of_day_s"] = t0 % _DAY
    say(
        f"{name}: {scan.n_sentences:,} sentences -> {index.size:,} samples at dt {grid.step:g} s"
        + (f" from {meta['start_time']}" if "start_time" in meta else "")
    )
    return Record.from_arrays(**arrays, meta=meta, max_gap_s=1.5 * grid.step)


FORMAT = SourceFormat("nmea", load_nmea, looks_like_nmea, fallback=True, options=("max_gap_s",))
"""The NMEA 0183 format of :func:`shipgym.sysid.io.load` (a fallback: after the formats with a
header of their own, before any delimited table)."""
