"""The measured manoeuvring records the package knows, and where they are on this machine.

Every dataset is a set of files in a public GitHub repository, read at a pinned commit (the
origin URL is ``https://raw.githubusercontent.com/<owner>/<repo>/<commit>/<path>``) and checked
against its SHA-256 written here. Nothing is copied into the package: the files are fetched into
a user cache (:func:`fetch`; ``shipgym data fetch NAME|all``), in one folder per dataset laid out
like the project's ``measured`` folder, so that :func:`shipgym.sysid.data.load_all` reads either.

Where a dataset is found, in order (:func:`path`):

1. ``$SHIPGYM_MEASURED_DATA``: an existing copy of the whole ``measured`` folder, used in place;
2. the user cache that :func:`fetch` fills: ``$SHIPGYM_DATA_DIR`` when set, else
   ``platformdirs.user_cache_dir("shipgym")/measured``.

``$SHIPGYM_DATA_MIRROR`` (a local folder, ``file://`` or an ``http(s)://`` base, laid out like
the ``measured`` folder) replaces the origin URLs for :func:`fetch`; the same SHA-256 check
applies. Downloads use pooch (with a tqdm progress bar when tqdm is installed); a dataset with a
non-commercial licence has its licence and citations printed before it is downloaded.

The datasets, their origins and conventions are described file by file in the ``SOURCES.md`` of
the project's ``measured`` folder; the citations to give are in :attr:`Dataset.citation`.
"""

from __future__ import annotations

import fnmatch
import os
import sys
import tempfile
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

__all__ = [
    "DATASETS",
    "DATA_DIR_ENV",
    "MEASURED_DATA_ENV",
    "MIRROR_ENV",
    "DataFile",
    "Dataset",
    "cache_dir",
    "expand_records",
    "fetch",
    "files",
    "format_size",
    "get",
    "list_datasets",
    "measured_root",
    "path",
]

MEASURED_DATA_ENV = "SHIPGYM_MEASURED_DATA"
"""Environment variable naming an existing copy of the whole ``measured`` folder (used in place)."""
DATA_DIR_ENV = "SHIPGYM_DATA_DIR"
"""Environment variable naming the folder :func:`fetch` writes to (default: the user cache)."""
MIRROR_ENV = "SHIPGYM_DATA_MIRROR"
"""Environment variable naming a mirror (local folder or URL base) that replaces the origins."""

_RAW = "https://raw.githubusercontent.com"
_CHUNK = 1 << 20  # bytes copied per progress update from a local mirror


@dataclass(frozen=True)
class DataFile:
    """One file of a dataset.

    Attributes
    ----------
    name : str
        Path inside the dataset's folder (``zigzag/zigzag_31-Jul-2020_13_04_24.csv``).
    url : str
        Origin at the pinned commit.
    sha256 : str
        SHA-256 of the file's bytes (hex).
    size : int
        Size [bytes].
    """

    name: str
    url: str
    sha256: str
    size: int


@dataclass(frozen=True)
class Dataset:
    """A measured dataset: what it is, the licence and citations, and its files.

    Attributes
    ----------
    name : str
        Short name (``marin-kvlcc2``), the argument of ``shipgym data`` and :func:`fetch`.
    folder : str
        Its folder in the ``measured`` layout (``marin_kvlcc2``).
    vessel, kind, runs : str
        The ship, the kind of test and the runs it holds.
    licence : str
        The terms of the origin.
    citation : tuple of str
        What to cite when the data are used.
    files : tuple of DataFile
        Its files, sorted by name.
    non_commercial : bool
        The licence forbids commercial use (printed before every download).
    """

    name: str
    folder: str
    vessel: str
    kind: str
    runs: str
    licence: str
    citation: tuple[str, ...]
    files: tuple[DataFile, ...]
    non_commercial: bool = False

    @property
    def size(self) -> int:
        """Total size of its files [bytes]."""
        return sum(f.size for f in self.files)


def _origin(
    repo: str, commit: str, directory: str, entries: Iterable[tuple[str, int, str]]
) -> tuple[DataFile, ...]:
    """The files ``(name, size, sha256)`` under ``directory`` of ``repo`` at ``commit``."""
    base = f"{_RAW}/{repo}/{commit}/{directory}"
    return tuple(DataFile(name, f"{base}/{name}", sha, size) for name, size, sha in entries)


_SYSID_REPO = "martinlarsalbert/System-identification-of-Vessel-Manoeuvring-Models"
_SYSID_HEAD = "4b7ce53f0cc8ac159126fdda7d45e30c540be2d8"
_SIMMAN = (
    "F. Stern et al. (2011), Experience from SIMMAN 2008: the first workshop on verification "
    "and validation of ship maneuvering simulation methods, J. Ship Research 55(2):135-147"
)

#: Every dataset the package knows, by name.
DATASETS: dict[str, Dataset] = {
    d.name: d
    for d in (
        Dataset(
            name="sspa-zigzag",
            folder="sspa_blog_zigzag",
            vessel="SSPA ship model",
            kind="free-running model test",
            runs="1 zigzag 20/20",
            licence="Apache-2.0",
            citation=(
                "M. Alexandersson (2020), First order Nomoto model for ship maneuvering "
                "dynamics, blog post, github.com/martinlarsalbert/blog (SSPA model test)",
            ),
            files=_origin(
                "martinlarsalbert/blog",
                "494d2b733705a721bd26cac6330951982e0d2850",
                "_notebooks",
                [
                    (
                        "example_zigzag.csv",
                        205615,
                        "40500ac23bb95184a5eb5c8942626d8b13a2c9fbd726c3a5fbdad7b7cfe760d9",
                    ),
                ],
            ),
        ),
        Dataset(
            name="marin-kvlcc2",
            folder="marin_kvlcc2",
            vessel="KVLCC2 (at full scale)",
            kind="free-running model test",
            runs="4 zigzag, 2 turning",
            licence="none stated (SIMMAN 2008)",
            citation=(
                "MARIN free-running model tests of KVLCC2 for SIMMAN 2008",
                _SIMMAN,
            ),
            files=_origin(
                _SYSID_REPO,
                _SYSID_HEAD,
                "data/01_raw/kvlcc2",
                [
                    (
                        "MARIN_FREE_KVLCC2_tc_-35_m.dat",
                        1646121,
                        "65b54ac82aa6b48e5851f7898a6349688ed3391c86c7ff79eeaa758125fb815d",
                    ),
                    (
                        "MARIN_FREE_KVLCC2_tc_35_m.dat",
                        1613413,
                        "9bba1c548ed2972f24249d862f254cfe3d0cb68475078cde0e9b5f9f2ead5b7f",
                    ),
                    (
                        "MARIN_FREE_KVLCC2_zz_-10_m.dat",
                        444947,
                        "b4de80bc3fbcd60cb4b2ea25a08a6831c7008fb0150425cfc8ad3690766da241",
                    ),
                    (
                        "MARIN_FREE_KVLCC2_zz_-20_m.dat",
                        516291,
                        "6db9f281ee2c1f35b7b2b28925710280d14126e60e444f53e2ca6ad7d4aaefd0",
                    ),
                    (
                        "MARIN_FREE_KVLCC2_zz_10_m.dat",
                        441885,
                        "80fe4bc493d5fe0923ee7fb7581c8351bac35c9c4201fb48c4cae52deb6c166a",
                    ),
                    (
                        "MARIN_FREE_KVLCC2_zz_20_m.dat",
                        517804,
                        "62af7e3af28c99e35aa363caf618e5a70588f9c8742b0bc4df9ac9d802c16be3",
                    ),
                ],
            ),
        ),
        Dataset(
            name="hsva-kvlcc2",
            folder="hsva_kvlcc2",
            vessel="KVLCC2, 7 m model",
            kind="free-running model test",
            runs="13 zigzag",
            licence="none stated (SIMMAN 2008)",
            citation=(
                "A. Cura Hochbaum (2006), SIMMAN model test report: KVLCC1 and 2 free-running "
                "tests, HSVA",
                _SIMMAN,
            ),
            files=_origin(
                _SYSID_REPO,
                _SYSID_HEAD,
                "data/01_raw/kvlcc2_hsva/raw_data",
                [
                    (
                        "HSVA_CPMC_KVLCC2_Z_05_01.dat",
                        658597,
                        "169305b6aa1a2dee0c1a498708228fde1db04f0e0a913ad31c3186e99fb61766",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_10_01.dat",
                        749398,
                        "2b2b11bc5732e45eba96bf61fcf8ef6d97b40c67cb424cf636cd58d8285a0425",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_10_05.dat",
                        794798,
                        "db2b9921264d4a2b998d259d001adb016c7368dd7ac1772dbeb96037875469b3",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_10_10_P.dat",
                        299956,
                        "fd3a1508e2c6f5fda46145a104c227789fbfa6a1847dd33723510872307467c4",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_10_10_S.dat",
                        304501,
                        "8b83dc0d1eea93f96a60d1a5d8d60f8b23c2f55b356d8b45d3f9a1cbdf94fb90",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_15_01.dat",
                        749398,
                        "3e5de380bf7a6b10fe2c650edeae01fdc8df5361e27a40ff0aa1b184cb629b6f",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_15_05.dat",
                        840198,
                        "d9e4c4669fabe7c05c6c701909f904564fd2a5a6454bbec6bf4ae5921000b140",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_20_05.dat",
                        803878,
                        "671b46a1f98e35b1b15d1aede74f909b8d3e2a4f1cb81cb69b476eb382bb4e76",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                        862916,
                        "6df42ab1dd49d481ce28172234d114018c645e45abbf1bcd609c70292c77830a",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_20_10_S.dat",
                        862921,
                        "5fdf062d6077f3ed7da1ef89354d335d3a4fb89f5be4b2c448d77490ee0f01f4",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_25_05.dat",
                        840198,
                        "f9ea9d7e22e89e02fbd82be2d6e61c9b36424a9a2b54b43143775397e047e518",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_30_05.dat",
                        908298,
                        "799303a2e29b3e8aaa178adffdf1a0f0179483f2593f290c3110263e85bf4c3d",
                    ),
                    (
                        "HSVA_CPMC_KVLCC2_Z_35_05.dat",
                        953698,
                        "6c2be03f2d6cdaf512c191b232352d040e8d7e64c286a2d4cac2de293dcc4796",
                    ),
                ],
            ),
        ),
        Dataset(
            name="usv-field",
            folder="usv_field",
            vessel="3.6 m twin-hull USV",
            kind="open-water field test",
            runs="1 zigzag, 1 turning",
            licence="none stated",
            citation=(
                "M. Alexandersson, X. Zhang, W. Mao, J. W. Ringsberg (2022), A comparison of "
                "ship manoeuvrability models to approximate ship navigation trajectories, "
                "Ships and Offshore Structures, doi:10.1080/17445302.2022.2067409",
            ),
            files=_origin(
                _SYSID_REPO,
                "47cfd8bb4b99cd59fb3843f6c02c79ea0a1c3813",
                "data/01_raw/USV",
                [
                    (
                        "turnningdata_xy.csv",
                        37405,
                        "73eb2b3d2d80cea5ce3745c0c06204278e57f7fe315371c1124794dba20ced78",
                    ),
                    (
                        "zigzag_30_inter_xy.csv",
                        110543,
                        "fb0a9d6ef0c6e1b5d3a374a46637b878e08044491d412a0319d045fe1e8cd773",
                    ),
                ],
            ),
        ),
        Dataset(
            name="esso-osaka",
            folder="esso_osaka_frt",
            vessel="Esso Osaka, 3 m model",
            kind="free-running, outdoor pond",
            runs="9 zigzag, 4 turning, 2 random",
            licence="CC BY-NC 4.0",
            citation=(
                "FRT-DS-ESSO, Osaka University (github.com/NAOE-5thLab/FRT-DS-ESSO)",
                "K. Wakita et al. (2022), J. Mar. Sci. Technol. 27:772-785, "
                "doi:10.1007/s00773-021-00867-1",
                "Y. Miyauchi et al. (2022), J. Mar. Sci. Technol. 27:1065-1083, "
                "doi:10.1007/s00773-022-00889-3",
            ),
            non_commercial=True,
            files=_origin(
                "NAOE-5thLab/FRT-DS-ESSO",
                "e694dfd62932bff755f3bc975b5863d649023bc0",
                "data",
                [
                    (
                        "random/random_06-Aug-2020_16_24_25_3.csv",
                        1506781,
                        "95344c92c05ccb60a1fa31a32ab02c85a9927b2581870721433b10d51458e7b9",
                    ),
                    (
                        "random/random_06-Aug-2020_16_24_25_4.csv",
                        1294615,
                        "61dcab5b97f0a039ce59ff18a5b6d6a67f1d35e0b1cdff536ac9192b8c89cc52",
                    ),
                    (
                        "turning/turn_14-Oct-2020_14_29_49.csv",
                        910814,
                        "0776c50eedc8357314d725800b58815301c85c36fa200a1e76838abfe6d86448",
                    ),
                    (
                        "turning/turn_14-Oct-2020_14_56_07.csv",
                        640432,
                        "d65279df69e217b72ab4249ccad5565425cfbc3e58dc507ce3fe149bb8cbbe09",
                    ),
                    (
                        "turning/turn_14-Sep-2020_13_39_32.csv",
                        748721,
                        "aedb10b620e00008acb2332ec180ca17a355cb9e2acba72244ebbfb167a9c7df",
                    ),
                    (
                        "turning/turn_14-Sep-2020_14_16_04.csv",
                        867906,
                        "b7075a503a922d58ab0da91c3ee15b55bb9cede0d51ed5f4fb26277fac506775",
                    ),
                    (
                        "zigzag/zigzag_31-Jul-2020_13_04_24.csv",
                        302365,
                        "37178ee5ca940a3735bf7b7d4f3a30437e2760c32999f23cb8c8178f14879729",
                    ),
                    (
                        "zigzag/zigzag_31-Jul-2020_13_14_21.csv",
                        261597,
                        "14dd0b5563df478f5adc28f2f3ca5f34cc58a21a163bb3e75375af9be135f532",
                    ),
                    (
                        "zigzag/zigzag_31-Jul-2020_13_22_52.csv",
                        351648,
                        "47d317d8405f88c524fc3e6646224ab4500c9b05184339dd35d14200a71cd8ff",
                    ),
                    (
                        "zigzag/zigzag_31-Jul-2020_13_29_19.csv",
                        274978,
                        "72523ffd6240cd441a9ab32c0a0ab8dfb52b120b7e7e9be365ff3e51cced022d",
                    ),
                    (
                        "zigzag/zigzag_31-Jul-2020_13_42_53.csv",
                        394526,
                        "17eef92785876f90d15bdbce18e381b3afed3f032bacdff4f702e6ab5f1d7ed7",
                    ),
                    (
                        "zigzag/zigzag_31-Jul-2020_13_50_28.csv",
                        247909,
                        "e04f52593cc350281dc2d0b39750a48253fff9e35b3be11d28fc8fa157bbdffa",
                    ),
                    (
                        "zigzag/zigzag_31-Jul-2020_13_57_45.csv",
                        230153,
                        "6047e035a67745103aa56924e500c3eeb4486f82476e6933e563ca9589db4b68",
                    ),
                    (
                        "zigzag/zigzag_31-Jul-2020_14_03_39.csv",
                        298386,
                        "d6b7e81950d278c77b21f05f58c8b67a86a1e0f6d43ec57781bb8b9620e01480",
                    ),
                    (
                        "zigzag/zigzag_31-Jul-2020_14_10_05.csv",
                        310144,
                        "b59c883731ee5f32ef896c80abf11ade212b815001e32d7b2c109d0bd9e27ed2",
                    ),
                ],
            ),
        ),
        Dataset(
            name="gunnerus-seatrials",
            folder="gunnerus_seatrials",
            vessel="R/V Gunnerus, 33.9 m",
            kind="full-scale sea trials",
            runs="1 record: 2.5 h of turns",
            licence="GPL-3.0-or-later",
            citation=(
                "NTNU-MCS, MCSim_python (github.com/NTNU-MCS/MCSim_python): R/V Gunnerus "
                "manoeuvring tests of 27 October 2022",
            ),
            files=_origin(
                "NTNU-MCS/MCSim_python",
                "0d21563f62d9dca7d90355234631d9d3ffa0d092",
                "dev/mathima/RVG_maneuvering",
                [
                    (
                        "RVG_ManeuveringTests.csv",
                        3199352,
                        "f9fd7e9d87a8afead5ff5da053c967e501a871ad34d7a90dfee00ae33c23c193",
                    ),
                ],
            ),
        ),
    )
}


def list_datasets() -> list[Dataset]:
    """Every dataset the package knows, in the order of :data:`DATASETS`."""
    return list(DATASETS.values())


def get(name: str) -> Dataset:
    """The dataset called ``name``.

    Raises
    ------
    ValueError
        If no dataset has that name (the message lists the known names).
    """
    try:
        return DATASETS[name]
    except KeyError:
        raise ValueError(
            f"unknown dataset {name!r}; expected one of {', '.join(DATASETS)}"
        ) from None


def format_size(n_bytes: int) -> str:
    """A size in decimal units: ``3.2 MB``, ``206 kB``."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n_bytes >= scale:
            value = n_bytes / scale
            return f"{value:.1f} {unit}" if value < 10 else f"{value:.0f} {unit}"
    return f"{n_bytes} B"


def cache_dir() -> Path:
    """The folder :func:`fetch` writes to: ``$SHIPGYM_DATA_DIR``, else the user cache
    (``platformdirs.user_cache_dir("shipgym")/measured``)."""
    env = os.environ.get(DATA_DIR_ENV)
    if env:
        return Path(env).expanduser()
    import platformdirs

    return Path(platformdirs.user_cache_dir("shipgym")) / "measured"


def _in_place_root() -> Path | None:
    env = os.environ.get(MEASURED_DATA_ENV)
    return Path(env).expanduser() if env else None


def measured_root() -> Path:
    """The ``measured`` folder: ``$SHIPGYM_MEASURED_DATA`` when set, else :func:`cache_dir`
    (where :func:`fetch` puts the datasets, one folder each)."""
    return _in_place_root() or cache_dir()


def _complete(dataset: Dataset, root: Path) -> bool:
    folder = root / dataset.folder
    return all((folder / f.name).is_file() for f in dataset.files)


def path(name: str) -> Path:
    """The folder of dataset ``name`` on this machine (its files present, not re-hashed).

    Raises
    ------
    ValueError
        If ``name`` is not a dataset's name.
    FileNotFoundError
        If it is in neither ``$SHIPGYM_MEASURED_DATA`` nor the cache; the message names the
        command that fetches it.
    """
    dataset = get(name)
    roots = [r for r in (_in_place_root(), cache_dir()) if r is not None]
    for root in roots:
        if _complete(dataset, root):
            return root / dataset.folder
    raise FileNotFoundError(
        f"dataset {name!r} is not on this machine (looked in "
        f"{', '.join(str(r / dataset.folder) for r in roots)}); fetch it with: "
        f"shipgym data fetch {name}"
    )


def files(name: str) -> list[Path]:
    """The files of dataset ``name`` on this machine (:func:`path`), in the registry's order."""
    folder = path(name)
    return [folder / f.name for f in get(name).files]


def expand_records(args: Iterable[str]) -> list[str]:
    """Command-line record arguments with dataset names replaced by their files.

    An argument that is an existing path is kept as it is. ``NAME`` (a dataset's name) becomes
    all its files; ``NAME/PATTERN`` the files whose name, or path inside the dataset, matches the
    shell pattern (``marin-kvlcc2/MARIN_*zz*``, ``esso-osaka/zigzag/*``). Anything else is kept
    as it is, for the loader to report.

    Raises
    ------
    ValueError
        If a pattern matches no file of its dataset (the message lists them).
    FileNotFoundError
        If a named dataset has not been fetched (:func:`path`).
    """
    out: list[str] = []
    for arg in args:
        name, _, pattern = arg.partition("/")
        if Path(arg).exists() or name not in DATASETS:
            out.append(arg)
            continue
        folder = path(name)
        names = [f.name for f in DATASETS[name].files]
        if pattern:
            names = [
                n for n in names
                if fnmatch.fnmatch(n, pattern) or fnmatch.fnmatch(Path(n).name, pattern)
            ]  # fmt: skip
            if not names:
                raise ValueError(
                    f"{arg!r} matches no file of dataset {name!r}; its files are "
                    f"{', '.join(f.name for f in DATASETS[name].files)}"
                )
        out.extend(str(folder / n) for n in names)
    return out


def _stderr(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def _silent(_message: str) -> None:
    return None


def _has_tqdm() -> bool:
    try:
        import tqdm  # noqa: F401
    except ImportError:
        return False
    return True


def _count(items: Sequence[DataFile]) -> str:
    return f"{len(items)} file{'' if len(items) == 1 else 's'}"


def _sha256(file: Path) -> str:
    """The SHA-256 of a file (pooch's hash, the one check of every source)."""
    import pooch

    return pooch.file_hash(str(file), alg="sha256")


def _source(dataset: Dataset, item: DataFile, mirror: str | None) -> str:
    """Where ``item`` is read from: the mirror's copy (folder or URL), else its origin."""
    if not mirror:
        return item.url
    if mirror.startswith(("http://", "https://")):
        return f"{mirror.rstrip('/')}/{dataset.folder}/{item.name}"
    return str(Path(mirror.removeprefix("file://")).expanduser() / dataset.folder / item.name)


def _transfer(source: str, target: Path, size: int, label: str, bar: bool) -> None:
    """Write ``source`` (URL: pooch's downloader; local file: a copy) to the file ``target``,
    with a tqdm bar of ``size`` bytes labelled ``label`` when ``bar``."""
    progress = None
    if bar:
        from tqdm import tqdm

        progress = tqdm(total=size, unit="B", unit_scale=True, desc=label, leave=True)
    try:
        if source.startswith(("http://", "https://")):
            import pooch

            downloader = pooch.HTTPDownloader(progressbar=False if progress is None else progress)
            try:
                downloader(source, str(target), None)
            except OSError as exc:  # requests' errors are OSErrors with pages of detail
                status = getattr(getattr(exc, "response", None), "status_code", None)
                reason = f"HTTP {status}" if status else type(exc).__name__
                raise OSError(
                    f"cannot download {source} ({reason}); check the address and the "
                    f"connection, or set ${MIRROR_ENV} to a copy laid out like the measured folder"
                ) from exc
        else:
            with open(source, "rb") as src, open(target, "wb") as dst:
                while chunk := src.read(_CHUNK):
                    dst.write(chunk)
                    if progress is not None:
                        progress.update(len(chunk))
    finally:
        if progress is not None:
            progress.close()


def _fetch_file(dataset: Dataset, item: DataFile, target: Path, source: str, bar: bool) -> None:
    """Fetch one file into ``target`` through a temporary file beside it, renamed only when its
    SHA-256 is the registry's (removed otherwise)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp_name = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".part")
    os.close(fd)
    tmp = Path(tmp_name)
    try:
        _transfer(source, tmp, item.size, item.name, bar)
        digest = _sha256(tmp)
        if digest != item.sha256:
            raise ValueError(
                f"{source} has SHA-256 {digest}, expected {item.sha256} (file {item.name} of "
                f"dataset {dataset.name!r}); not kept"
            )
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)


def _licence_notice(dataset: Dataset) -> str:
    cites = "\n".join(f"  - {c}" for c in dataset.citation)
    return (
        f"{dataset.name}: licence {dataset.licence}, non-commercial use only; when you use "
        f"these data, cite:\n{cites}"
    )


def _verify_in_place(dataset: Dataset, folder: Path) -> None:
    for item in dataset.files:
        digest = _sha256(folder / item.name)
        if digest != item.sha256:
            raise ValueError(
                f"{folder / item.name} (in ${MEASURED_DATA_ENV}) has SHA-256 {digest}, expected "
                f"{item.sha256}; restore the copy or unset {MEASURED_DATA_ENV}"
            )


def _fetch_one(
    dataset: Dataset,
    mirror: str | None,
    say: Callable[[str], None],
    notice: Callable[[str], None],
    bar: bool,
) -> Path:
    in_place = _in_place_root()
    if in_place is not None and _complete(dataset, in_place):
        folder = in_place / dataset.folder
        _verify_in_place(dataset, folder)
        say(f"{dataset.name}: {_count(dataset.files)} verified in place in {folder}")
        return folder
    folder = cache_dir() / dataset.folder
    todo = [
        f for f in dataset.files
        if not (folder / f.name).is_file() or _sha256(folder / f.name) != f.sha256
    ]  # fmt: skip
    if not todo:
        say(f"{dataset.name}: {_count(dataset.files)} already in {folder}")
        return folder
    if dataset.non_commercial:
        notice(_licence_notice(dataset))
    say(
        f"{dataset.name}: fetching {_count(todo)} ({format_size(sum(f.size for f in todo))}) "
        f"from {mirror or 'the origin'} into {folder}"
    )
    for item in todo:
        _fetch_file(dataset, item, folder / item.name, _source(dataset, item, mirror), bar)
    return folder


def fetch(
    name: str = "all",
    *,
    progress: bool = True,
    notice: Callable[[str], None] | None = None,
    mirror: str | None = None,
) -> Path:
    """Fetch dataset ``name`` (or ``"all"``) into the cache, each file checked by its SHA-256.

    A dataset found complete in ``$SHIPGYM_MEASURED_DATA`` is verified there and not copied.
    Files already in the cache with the right hash are kept. Each file is written to a
    temporary file beside its target and renamed only when its SHA-256 matches, so a failed or
    corrupted transfer leaves nothing behind.

    Parameters
    ----------
    name : str
        A dataset's name (:data:`DATASETS`) or ``"all"``.
    progress : bool
        A line per dataset and a progress bar per file (tqdm, when installed).
    notice : callable, optional
        Takes the progress lines and the licence notice printed before a non-commercial dataset
        is downloaded (always, whatever ``progress``); default: print to stderr.
    mirror : str, optional
        A local folder, ``file://`` or ``http(s)://`` base laid out like the ``measured``
        folder, read instead of the origins; default: ``$SHIPGYM_DATA_MIRROR`` when set.

    Returns
    -------
    pathlib.Path
        The dataset's folder; for ``"all"``, the folder holding them (:func:`measured_root`
        when every dataset is there, else :func:`cache_dir`).

    Raises
    ------
    ValueError
        For an unknown name, or a file whose SHA-256 is not the registry's.
    OSError
        If a source cannot be read (network error, missing mirror file).
    """
    chosen = list_datasets() if name == "all" else [get(name)]
    notice = notice or _stderr
    say = notice if progress else _silent
    bar = progress and _has_tqdm()
    mirror = mirror or os.environ.get(MIRROR_ENV) or None
    folders = [_fetch_one(d, mirror, say, notice, bar) for d in chosen]
    if name != "all":
        return folders[0]
    root = measured_root()
    return root if all(f.parent == root for f in folders) else cache_dir()
