"""Tests of the measured-data registry (:mod:`shipgym.datasets`) and ``shipgym data``.

The registry is checked against the project's local mirror of the measured folder
(``$SHIPGYM_MEASURED_DATA``, set by the conftest to ``../shared/data/measured`` beside the
checkout): every file's SHA-256 and size, and no file of the mirror left out. Fetches read that
mirror (as a folder, and over HTTP from a server on this machine) into ``tmp_path``.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import http.server
import io
import re
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from shipgym import datasets
from shipgym.cli import main
from shipgym.datasets import DATA_DIR_ENV, DATASETS, MEASURED_DATA_ENV, MIRROR_ENV

MIRROR = datasets.measured_root()
pytestmark = pytest.mark.skipif(
    not MIRROR.is_dir(),
    reason=f"measured-data mirror not found at {MIRROR} (set {MEASURED_DATA_ENV})",
)
#: every file of the registry, as ``folder/name`` in the measured layout
REGISTERED = {f"{d.folder}/{f.name}" for d in DATASETS.values() for f in d.files}
N_FILES = len(REGISTERED)


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty cache in ``tmp_path``, no in-place copy and no mirror in the environment."""
    folder = tmp_path / "cache"
    monkeypatch.setenv(DATA_DIR_ENV, str(folder))
    monkeypatch.delenv(MEASURED_DATA_ENV, raising=False)
    monkeypatch.delenv(MIRROR_ENV, raising=False)
    return folder


def _mirror_of(tmp_path: Path, name: str) -> Path:
    """A mirror in ``tmp_path`` holding a copy of dataset ``name`` only."""
    root = tmp_path / "mirror"
    dataset = DATASETS[name]
    for item in dataset.files:
        target = root / dataset.folder / item.name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes((MIRROR / dataset.folder / item.name).read_bytes())
    return root


def _files_under(folder: Path) -> set[str]:
    return {p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file()}


# ------------------------------------------------------------------------------------------
# the registry


def test_registry_hashes_and_sizes_match_the_mirror() -> None:
    for dataset in DATASETS.values():
        for item in dataset.files:
            f = MIRROR / dataset.folder / item.name
            assert f.stat().st_size == item.size, f
            assert _sha256(f) == item.sha256, f


def test_every_data_file_of_the_mirror_is_in_the_registry() -> None:
    on_disk = {n for n in _files_under(MIRROR) if not n.endswith(".md")}
    assert on_disk == REGISTERED
    assert {p.name for p in MIRROR.iterdir() if p.is_dir()} == {d.folder for d in DATASETS.values()}
    assert N_FILES == 1 + 6 + 13 + 2 + 15 + 1


def test_registry_entries_are_complete_and_pinned() -> None:
    pinned = re.compile(r"^https://raw\.githubusercontent\.com/[\w.-]+/[\w.-]+/[0-9a-f]{40}/")
    assert list(DATASETS) == [
        "sspa-zigzag",
        "marin-kvlcc2",
        "hsva-kvlcc2",
        "usv-field",
        "esso-osaka",
        "gunnerus-seatrials",
    ]
    for name, d in DATASETS.items():
        assert d.name == name and d.vessel and d.kind and d.runs and d.licence and d.citation
        assert [f.name for f in d.files] == sorted(f.name for f in d.files)
        for f in d.files:
            assert pinned.match(f.url) and f.url.endswith("/" + f.name), f.url
            assert re.fullmatch(r"[0-9a-f]{64}", f.sha256)
    assert [d.name for d in datasets.list_datasets() if d.non_commercial] == ["esso-osaka"]
    assert DATASETS["esso-osaka"].licence == "CC BY-NC 4.0"
    assert datasets.format_size(DATASETS["gunnerus-seatrials"].size) == "3.2 MB"
    assert datasets.format_size(DATASETS["sspa-zigzag"].size) == "206 kB"


def test_unknown_names_list_the_known_ones() -> None:
    for call in (datasets.get, datasets.path, datasets.files, datasets.fetch):
        with pytest.raises(ValueError, match="unknown dataset 'kvlcc3'") as info:
            call("kvlcc3")
        assert all(name in str(info.value) for name in DATASETS)


# ------------------------------------------------------------------------------------------
# where the data are found


def test_in_place_copy_is_used_without_copying(tmp_path: Path, monkeypatch) -> None:
    monkeypatch.setenv(MEASURED_DATA_ENV, str(MIRROR))
    monkeypatch.setenv(DATA_DIR_ENV, str(tmp_path / "cache"))
    from shipgym.sysid.data import measured_root

    assert measured_root() == datasets.measured_root() == MIRROR
    assert datasets.path("hsva-kvlcc2") == MIRROR / "hsva_kvlcc2"
    assert datasets.fetch("hsva-kvlcc2", notice=lambda _m: None) == MIRROR / "hsva_kvlcc2"
    assert datasets.fetch("all", progress=False) == MIRROR
    assert not (tmp_path / "cache").exists()


def test_without_a_copy_the_root_is_the_cache(cache: Path) -> None:
    from shipgym.sysid.data import measured_root

    assert measured_root() == datasets.cache_dir() == cache


def test_user_cache_by_default(monkeypatch: pytest.MonkeyPatch) -> None:
    import platformdirs

    monkeypatch.delenv(DATA_DIR_ENV, raising=False)
    assert datasets.cache_dir() == Path(platformdirs.user_cache_dir("shipgym")) / "measured"


def test_path_of_an_absent_dataset_names_the_fetch_command(cache: Path) -> None:
    with pytest.raises(FileNotFoundError, match="shipgym data fetch esso-osaka") as info:
        datasets.path("esso-osaka")
    assert str(cache / "esso_osaka_frt") in str(info.value)


# ------------------------------------------------------------------------------------------
# fetch


@pytest.mark.filterwarnings("ignore::shipgym.sysid.data.SysidDataWarning")
def test_fetch_all_from_a_local_mirror(cache: Path, capsys: pytest.CaptureFixture[str]) -> None:
    pytest.importorskip("tqdm")  # the progress bars
    assert datasets.fetch("all", mirror=str(MIRROR)) == cache
    err = capsys.readouterr().err
    assert _files_under(cache) == REGISTERED
    for d in DATASETS.values():
        assert datasets.path(d.name) == cache / d.folder
        for f in datasets.files(d.name):
            assert _sha256(f) == _sha256(MIRROR / d.folder / f.relative_to(cache / d.folder))
        assert f"{d.name}: fetching {len(d.files)} file" in err
    # a bar per file, filled; the non-commercial licence and its citations before that dataset
    assert err.count("100%") >= N_FILES
    licence = err.index("esso-osaka: licence CC BY-NC 4.0, non-commercial use only")
    assert licence < err.index("random/random_06-Aug-2020_16_24_25_3.csv")
    assert "doi:10.1007/s00773-021-00867-1" in err and "doi:10.1007/s00773-022-00889-3" in err
    assert err.count("non-commercial") == 1
    # the fetched cache is a measured folder
    from shipgym.sysid.data import load, load_all

    assert len(load_all(cache)) == N_FILES  # one record a file
    assert load(datasets.files("usv-field")[1]).n == 420
    # a second fetch keeps the verified files: no transfer, no licence notice
    assert datasets.fetch("all") == cache
    again = capsys.readouterr().err
    assert "100%" not in again and "licence" not in again
    assert again.count("already in") == len(DATASETS)


def test_fetch_without_progress_still_prints_the_licence(
    cache: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    mirror = _mirror_of(tmp_path, "esso-osaka")
    notices: list[str] = []
    datasets.fetch("esso-osaka", progress=False, notice=notices.append, mirror=str(mirror))
    assert len(notices) == 1 and notices[0].startswith("esso-osaka: licence CC BY-NC 4.0")
    assert capsys.readouterr().err == ""
    assert len(datasets.files("esso-osaka")) == 15


def test_fetch_refuses_a_corrupted_file_and_keeps_nothing_of_it(
    cache: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    mirror = _mirror_of(tmp_path, "usv-field")
    bad = mirror / "usv_field" / "zigzag_30_inter_xy.csv"
    data = bytearray(bad.read_bytes())
    data[100] ^= 1  # one bit
    bad.write_bytes(bytes(data))
    monkeypatch.setenv(MIRROR_ENV, str(mirror))
    with pytest.raises(ValueError, match=r"zigzag_30_inter_xy\.csv") as info:
        datasets.fetch("usv-field", progress=False)
    message = str(info.value)
    assert f"SHA-256 {hashlib.sha256(bytes(data)).hexdigest()}" in message
    assert DATASETS["usv-field"].files[1].sha256 in message and "not kept" in message
    # the good file before it is kept (verified); nothing of the bad one, no temporary file
    assert _files_under(cache) == {"usv_field/turnningdata_xy.csv"}
    with pytest.raises(FileNotFoundError, match="shipgym data fetch usv-field"):
        datasets.path("usv-field")


def test_fetch_replaces_a_damaged_cached_file(cache: Path, tmp_path: Path) -> None:
    mirror = _mirror_of(tmp_path, "sspa-zigzag")
    target = datasets.fetch("sspa-zigzag", progress=False, mirror=str(mirror))
    (target / "example_zigzag.csv").write_text("damaged")
    datasets.fetch("sspa-zigzag", progress=False, mirror=f"file://{mirror}")
    assert _sha256(target / "example_zigzag.csv") == DATASETS["sspa-zigzag"].files[0].sha256


def test_fetch_refuses_a_changed_in_place_copy(tmp_path: Path, monkeypatch) -> None:
    copy = _mirror_of(tmp_path, "usv-field")
    (copy / "usv_field" / "turnningdata_xy.csv").write_text("changed")
    monkeypatch.setenv(MEASURED_DATA_ENV, str(copy))
    with pytest.raises(ValueError, match=f"turnningdata_xy.csv \\(in \\${MEASURED_DATA_ENV}\\)"):
        datasets.fetch("usv-field", progress=False)


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: object) -> None:
        return None


@pytest.fixture
def http_mirror(tmp_path: Path) -> Iterator[tuple[str, Path]]:
    """An HTTP server on this machine serving a mirror of sspa-zigzag and usv-field."""
    root = _mirror_of(tmp_path, "sspa-zigzag")
    _mirror_of(tmp_path, "usv-field")
    handler = functools.partial(_QuietHandler, directory=str(root))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/", root
    finally:
        server.shutdown()
        server.server_close()
        thread.join()


def test_fetch_over_http_with_pooch(
    cache: Path, http_mirror: tuple[str, Path], capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("tqdm")
    url, root = http_mirror
    folder = datasets.fetch("sspa-zigzag", mirror=url)
    assert _sha256(folder / "example_zigzag.csv") == DATASETS["sspa-zigzag"].files[0].sha256
    err = capsys.readouterr().err
    assert f"from {url} into {folder}" in err and "example_zigzag.csv" in err and "100%" in err
    # a missing file on the server: an OSError (HTTP 404), nothing kept
    (root / "usv_field" / "zigzag_30_inter_xy.csv").unlink()
    with pytest.raises(OSError, match=r"cannot download .*zigzag_30_inter_xy.csv \(HTTP 404\)"):
        datasets.fetch("usv-field", progress=False, mirror=url)
    assert _files_under(cache / "usv_field") == {"turnningdata_xy.csv"}


def test_fetch_without_a_connection_says_what_to_do(cache: Path) -> None:
    """Nothing listens on port 1: one line naming the file, the failure and the mirror
    variable, not the pages of a connection error."""
    with pytest.raises(OSError) as info:
        datasets.fetch("sspa-zigzag", progress=False, mirror="http://127.0.0.1:1")
    message = str(info.value)
    assert message.startswith("cannot download http://127.0.0.1:1/sspa_blog_zigzag/")
    assert "(ConnectionError)" in message and "SHIPGYM_DATA_MIRROR" in message
    assert "\n" not in message and len(message) < 300
    assert not (cache / "sspa_blog_zigzag").exists() or not any(
        (cache / "sspa_blog_zigzag").iterdir()
    )


# ------------------------------------------------------------------------------------------
# dataset names on the command line


def test_expand_records_names_patterns_and_paths(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    marin = MIRROR / "marin_kvlcc2"
    zz = datasets.expand_records(["marin-kvlcc2/MARIN_*zz*"])
    assert zz == [
        str(marin / f"MARIN_FREE_KVLCC2_zz_{a}_m.dat") for a in ("-10", "-20", "10", "20")
    ]
    assert len(datasets.expand_records(["hsva-kvlcc2"])) == 13
    assert len(datasets.expand_records(["esso-osaka/zigzag/*"])) == 9
    assert len(datasets.expand_records(["esso-osaka/turn_*"])) == 4
    # a real path is left alone, even one named like a dataset; other text is kept for the loader
    Path("usv-field").write_text("x")
    assert datasets.expand_records(["usv-field", "run.csv", str(marin)]) == [
        "usv-field",
        "run.csv",
        str(marin),
    ]
    with pytest.raises(ValueError, match="matches no file of dataset 'marin-kvlcc2'") as info:
        datasets.expand_records(["marin-kvlcc2/*.csv"])
    assert "MARIN_FREE_KVLCC2_tc_35_m.dat" in str(info.value)


def test_expand_records_of_an_absent_dataset(cache: Path) -> None:
    with pytest.raises(FileNotFoundError, match="shipgym data fetch gunnerus-seatrials"):
        datasets.expand_records(["gunnerus-seatrials"])


# ------------------------------------------------------------------------------------------
# shipgym data


def test_cli_data_list() -> None:
    code, out, _ = _run(["data", "list"])
    assert code == 0
    header, *rows = out.split("\n\n")[0].splitlines()
    assert header.split() == ["name", "vessel", "kind", "runs", "size", "licence", "fetched"]
    assert [r.split()[0] for r in rows] == list(DATASETS)
    assert all(r.endswith("yes") for r in rows)  # the mirror, in place
    esso = next(r for r in rows if r.startswith("esso-osaka"))
    assert "CC BY-NC 4.0" in esso and "8.6 MB" in esso
    assert "esso-osaka (non-commercial use only):" in out
    assert "doi:10.1080/17445302.2022.2067409" in out


def test_cli_data_path() -> None:
    code, out, _ = _run(["data", "path", "gunnerus-seatrials"])
    assert (code, out) == (0, f"{MIRROR / 'gunnerus_seatrials'}\n")
    code, out, _ = _run(["data", "path", "usv-field", "--files"])
    assert code == 0 and out.splitlines() == [str(p) for p in datasets.files("usv-field")]


def test_cli_data_errors(cache: Path) -> None:
    code, _, err = _run(["data", "path", "esso-osaka"])
    assert code == 1 and err.count("\n") == 1
    assert "shipgym data fetch esso-osaka" in err
    code, _, err = _run(["data", "fetch", "nope"])
    assert code == 2 and err.startswith("shipgym: error: unknown dataset 'nope'")


def test_cli_data_fetch(cache: Path, tmp_path: Path) -> None:
    pytest.importorskip("tqdm")
    mirror = _mirror_of(tmp_path, "usv-field")
    _mirror_of(tmp_path, "esso-osaka")
    code, out, err = _run(["data", "fetch", "usv-field", "--mirror", str(mirror)])
    assert (code, out) == (0, f"usv-field: {cache / 'usv_field'}\n")
    assert "turnningdata_xy.csv" in err and "100%" in err
    code, out, err = _run(["data", "fetch", "esso-osaka", "--mirror", str(mirror), "--quiet"])
    assert (code, out) == (0, f"esso-osaka: {cache / 'esso_osaka_frt'}\n")
    assert err.startswith("esso-osaka: licence CC BY-NC 4.0") and "100%" not in err


def test_cli_identify_takes_a_dataset_name(tmp_path: Path) -> None:
    out_json = tmp_path / "fit.json"
    code, out, _ = _run(
        ["identify", "sspa-zigzag", "--max-effects", "0", "--quiet", "--json", str(out_json)]
    )
    assert code == 0, out
    record = MIRROR / "sspa_blog_zigzag" / "example_zigzag.csv"
    assert out.startswith(f"shipgym identify {record} (sspa, 2073 samples")
    assert out_json.is_file()


def test_the_measured_data_page_lists_the_registry() -> None:
    """The table of ``docs/guide/data.md`` is the registry's, row for row."""
    from shipgym.datasets import format_size, list_datasets

    page = (Path(__file__).resolve().parents[1] / "docs" / "guide" / "data.md").read_text()
    rows = [
        [c.strip().strip("`") for c in line.strip().strip("|").split("|")]
        for line in page.splitlines()
        if line.startswith("| `")
    ]
    names = {d.name for d in list_datasets()}
    rows = [row for row in rows if row[0] in names or "-" in row[0]]
    expected = [
        [d.name, d.vessel, d.kind, d.runs, format_size(sum(f.size for f in d.files)), d.licence]
        for d in list_datasets()
    ]
    assert rows == expected
