"""Property-based hostile input for the environments and the record loader (Hypothesis).

Whatever a careless or hostile caller passes, nothing may crash the interpreter, raise anything
but ``ValueError``/``TypeError`` with a message, or hand back a non-finite number silently:

* every env's ``reset`` with random options (known keys with values of every kind, unknown
  keys), then a few steps with random actions: a refusal, or observations inside the
  observation space and finite rewards;
* ``shipgym.sysid.load`` on random bytes and on random canonical CSVs: a refusal, or a record
  whose channels are finite.

The models' public functions have their own module (``test_properties_models.py``).
"""

from __future__ import annotations

import math
import tempfile
import warnings
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

import shipgym  # noqa: F401  (registers the environments)
from shipgym.envs import ENV_IDS
from shipgym.envs.tasks import COMMON_OPTIONS
from shipgym.sysid import load

# one worker runs this file: its module fixtures are built once (pytest-xdist)
pytestmark = pytest.mark.xdist_group("test_properties")

SETTINGS = settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow], database=None
)

_ENVS: dict[str, gym.Env] = {}


def _env(env_id: str) -> gym.Env:
    """One env per id for the whole module (the kernels compile once)."""
    if env_id not in _ENVS:
        _ENVS[env_id] = gym.make(env_id).unwrapped
    return _ENVS[env_id]


@pytest.fixture(scope="module", autouse=True)
def _close_envs():
    yield
    for env in _ENVS.values():
        env.close()
    _ENVS.clear()


def _refusal(exc: BaseException) -> None:
    """A refusal must be a ValueError/TypeError that says something."""
    assert isinstance(exc, ValueError | TypeError), f"{type(exc).__name__}: {exc}"
    assert str(exc).strip(), f"{type(exc).__name__} without a message"


FLOATS = st.floats(allow_nan=True, allow_infinity=True, width=64)
SCALARS = st.one_of(
    FLOATS,
    st.integers(-(10**30), 10**30),
    st.booleans(),
    st.none(),
    st.text(max_size=4),
    st.complex_numbers(max_magnitude=1e3),
)
ARRAYS = hnp.arrays(
    dtype=st.sampled_from([np.float64, np.float32, np.int64, np.bool_, np.complex128]),
    shape=hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=12),
)
VALUES = st.one_of(
    SCALARS,
    ARRAYS,
    st.lists(FLOATS, max_size=12),
    st.lists(st.lists(FLOATS, min_size=2, max_size=2), max_size=8),
    st.dictionaries(st.text(max_size=6), SCALARS, max_size=3),
)


@st.composite
def _options(draw: st.DrawFn, env_id: str) -> dict[str, Any]:
    task = _env(env_id).task
    keys = sorted(COMMON_OPTIONS | task.task_options)
    names = list(task.model.state_names)
    options: dict[str, Any] = {}
    for key in draw(st.lists(st.sampled_from([*keys, "not_an_option"]), max_size=3, unique=True)):
        if key == "initial_state" and draw(st.booleans()):
            # a dict of named states: the most likely way to pass it, with hostile values
            options[key] = draw(
                st.dictionaries(st.sampled_from([*names, "nope"]), SCALARS, max_size=3)
            )
        else:
            options[key] = draw(VALUES)
    return options


@pytest.mark.parametrize("env_id", ENV_IDS)
@SETTINGS
@given(data=st.data())
def test_reset_options_are_refused_or_give_observations_in_the_space(
    env_id: str, data: st.DataObject
) -> None:
    env = _env(env_id)
    options = data.draw(_options(env_id), label="options")
    seed = data.draw(st.integers(0, 2**32 - 1), label="seed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            obs, _ = env.reset(seed=seed, options=options)
        except Exception as exc:  # the property is what it may raise
            _refusal(exc)
            return
    space = env.observation_space
    assert np.all(np.isfinite(obs)) and space.contains(obs.astype(space.dtype)), (options, obs)
    for _ in range(5):
        action = data.draw(
            hnp.arrays(np.float32, env.action_space.shape, elements=st.floats(-1, 1, width=32)),
            label="action",
        )
        obs, reward, terminated, truncated, _ = env.step(action)
        assert np.all(np.isfinite(obs)) and space.contains(obs.astype(space.dtype)), obs
        assert math.isfinite(reward), reward
        if terminated or truncated:
            break


def _load_text_or_bytes(content: bytes, name: str) -> None:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / name
        path.write_bytes(content)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                record = load(path)
            except Exception as exc:  # the property is what it may raise
                _refusal(exc)
                return
    for channel, values in record.channels().items():
        assert np.all(np.isfinite(values)), f"{channel} has non-finite values"


@SETTINGS
@given(content=st.binary(max_size=400), name=st.sampled_from(["x.csv", "x.txt", "x.dat", "x"]))
def test_random_bytes_into_load(content: bytes, name: str) -> None:
    _load_text_or_bytes(content, name)


_COLUMNS = ["time_s", "delta_rad", "psi_rad", "r_rad_s", "x_m", "y_m", "U_m_s", "rpm"]
_CELLS = st.one_of(
    FLOATS.map(repr),
    st.integers(-(10**6), 10**6).map(str),
    st.sampled_from(["", "nan", "inf", "-inf", "abc", "1e400", "0x10", " ", '"1"']),
)


@st.composite
def _canonical_csv(draw: st.DrawFn) -> bytes:
    lines = []
    if draw(st.booleans()):
        lines.append("# shipgym canonical record v1")
    for _ in range(draw(st.integers(0, 2))):
        key = draw(st.sampled_from(["source", "repairs", "notes", "dt", "x y"]))
        value = draw(st.sampled_from(['"a"', "5", '"abc"', "[1, 2]", "{", "null", '["ok"]']))
        lines.append(f"# {key}: {value}")
    cols = draw(st.lists(st.sampled_from(_COLUMNS), min_size=1, max_size=6))
    lines.append(",".join(cols))
    t = 0.0
    for _ in range(draw(st.integers(0, 30))):
        t += draw(st.sampled_from([0.5, 0.5, 0.5, 0.0, -1.0, 1e-9]))
        row = [draw(_CELLS) if c != "time_s" or draw(st.booleans()) else repr(t) for c in cols]
        lines.append(",".join(row[: draw(st.integers(len(row) - 1, len(row)))]))
    bom = b"\xef\xbb\xbf" if draw(st.booleans()) else b""
    return bom + "\n".join(lines).encode()


@SETTINGS
@given(content=_canonical_csv())
def test_random_canonical_csv_into_load(content: bytes) -> None:
    _load_text_or_bytes(content, "record.csv")


@SETTINGS
@given(
    data=hnp.arrays(
        np.float64,
        st.tuples(st.integers(20, 60), st.just(4)),
        elements=st.floats(-1e3, 1e3, allow_nan=False),
    )
)
def test_well_formed_random_records_load_with_finite_channels(data: np.ndarray) -> None:
    """Finite numbers under a valid header on an increasing clock: loaded or refused with a
    reason (unit checks may refuse a random heading), never non-finite."""
    rows = [f"{0.5 * k!r},{d!r},{p!r},{r!r}" for k, (d, p, r, _) in enumerate(data)]
    text = "time_s,delta_rad,psi_rad,r_rad_s\n" + "\n".join(rows) + "\n"
    _load_text_or_bytes(text.encode(), "record.csv")
