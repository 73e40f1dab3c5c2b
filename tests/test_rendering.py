"""Tests of :mod:`shipgym.envs.rendering` (offscreen top-down renderer)."""

from __future__ import annotations

import math

import matplotlib
import numpy as np
import pytest
from matplotlib.colors import to_rgb

from shipgym.envs.rendering import HULL_COLOR, TopDownRenderer

LENGTH = 40.0
BEAM = 10.0
HULL_RGB = np.array([round(255 * c) for c in to_rgb(HULL_COLOR)], dtype=np.int16)


def hull_pixels(frame: np.ndarray) -> np.ndarray:
    """Return ``(k, 2)`` pixel coordinates ``(col, row_up)`` of hull-coloured pixels.

    ``row_up`` counts upward from the bottom so that the returned cloud uses the plot's
    axes: column = east, row_up = north.
    """
    diff = np.abs(frame.astype(np.int16) - HULL_RGB).max(axis=2)
    rows, cols = np.nonzero(diff <= 6)
    return np.column_stack([cols, frame.shape[0] - 1 - rows]).astype(float)


def principal_angle(points: np.ndarray) -> float:
    """Angle (rad, from the image's up axis toward the right) of the major principal axis."""
    centred = points - points.mean(axis=0)
    cov = centred.T @ centred / len(points)
    eigvals, eigvecs = np.linalg.eigh(cov)
    east, north = eigvecs[:, np.argmax(eigvals)]
    return math.atan2(east, north)


@pytest.fixture
def renderer():
    r = TopDownRenderer(LENGTH, BEAM, "rgb_array", width=400, height=300, title="test")
    yield r
    r.close()


def test_rgb_array_shape_dtype_not_blank(renderer: TopDownRenderer) -> None:
    path = np.array([[0.0, 0.0], [100.0, 50.0], [200.0, 0.0]])
    trail = np.array([[-20.0, 0.0], [-10.0, 1.0], [0.0, 2.0]])
    frame = renderer.draw(
        0.0,
        0.0,
        0.3,
        trail=trail,
        path=path,
        target=(100.0, 50.0),
        target_heading=0.5,
        setpoint_heading=0.4,
        current_speed=0.5,
        current_direction=1.0,
        text="t = 1.0 s",
    )
    assert isinstance(frame, np.ndarray)
    assert frame.shape == (300, 400, 3)
    assert frame.dtype == np.uint8
    # Many distinct colours and a clear spread of intensities: not a blank image.
    assert frame.std() > 5.0
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) > 50
    assert len(hull_pixels(frame)) > 100


def test_frames_are_reproducible_and_independent(renderer: TopDownRenderer) -> None:
    first = renderer.draw(0.0, 0.0, 0.0)
    second = renderer.draw(0.0, 0.0, 0.0)
    assert first is not None and second is not None
    np.testing.assert_array_equal(first, second)
    # The returned frame must not alias the canvas buffer.
    renderer.draw(0.0, 0.0, 1.0)
    np.testing.assert_array_equal(first, second)


def test_ship_pixels_move_with_position(renderer: TopDownRenderer) -> None:
    frame0 = renderer.draw(0.0, 0.0, 0.0)
    assert frame0 is not None
    c0 = hull_pixels(frame0).mean(axis=0)
    # One ship length north: the ship moves up the image (row_up increases).
    frame1 = renderer.draw(LENGTH, 0.0, 0.0)
    assert frame1 is not None
    c1 = hull_pixels(frame1).mean(axis=0)
    assert c1[1] - c0[1] > 10.0
    assert abs(c1[0] - c0[0]) < 2.0
    # Then one ship length east: the ship moves right.
    frame2 = renderer.draw(LENGTH, LENGTH, 0.0)
    assert frame2 is not None
    c2 = hull_pixels(frame2).mean(axis=0)
    assert c2[0] - c1[0] > 10.0
    assert abs(c2[1] - c1[1]) < 2.0


def test_ship_is_centred_after_reset_view(renderer: TopDownRenderer) -> None:
    renderer.draw(0.0, 0.0, 0.0)
    renderer.draw(LENGTH, LENGTH, 0.0)
    renderer.reset_view()
    frame = renderer.draw(LENGTH, LENGTH, 0.0)
    assert frame is not None
    pts = hull_pixels(frame)
    # Bounding-box centre = midships (the area centroid lies aft because of the pointed bow).
    centre = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    np.testing.assert_allclose(centre, [199.5, 149.5], atol=2.5)


def test_heading_rotates_hull(renderer: TopDownRenderer) -> None:
    north = renderer.draw(0.0, 0.0, 0.0)
    east = renderer.draw(0.0, 0.0, math.pi / 2)
    assert north is not None and east is not None
    # Long axis vertical for psi = 0 and horizontal for psi = pi/2.
    a_north = principal_angle(hull_pixels(north))
    a_east = principal_angle(hull_pixels(east))
    assert abs(math.sin(a_north)) < 0.1
    assert abs(math.cos(a_east)) < 0.1

    # The bow (far end from the centroid in the heading direction) points the right way.
    def bow_offset(frame: np.ndarray, axis: int) -> float:
        pts = hull_pixels(frame)
        centred = pts[:, axis] - pts[:, axis].mean()
        # Pointed bow: fewer pixels at the bow end, so the mean lies toward the stern and
        # the farthest pixel is at the bow.
        return float(centred.max() + centred.min())

    assert bow_offset(north, axis=1) > 0.0  # bow up (north)
    assert bow_offset(east, axis=0) > 0.0  # bow right (east)


def test_oblique_heading_orientation(renderer: TopDownRenderer) -> None:
    frame = renderer.draw(0.0, 0.0, math.radians(30.0))
    assert frame is not None
    angle = principal_angle(hull_pixels(frame))
    # The principal axis has a sign ambiguity; compare modulo pi.
    err = (angle - math.radians(30.0) + math.pi / 2) % math.pi - math.pi / 2
    assert abs(err) < math.radians(4.0)


def test_view_fits_target(renderer: TopDownRenderer) -> None:
    near = renderer.draw(0.0, 0.0, 0.0)
    renderer.reset_view()
    far = renderer.draw(0.0, 0.0, 0.0, target=(10.0 * LENGTH, 0.0))
    assert near is not None and far is not None
    # Zooming out to fit the target makes the hull smaller on screen.
    assert len(hull_pixels(far)) < 0.5 * len(hull_pixels(near))


@pytest.mark.parametrize("mode", ["rgb", "Human", "ansi", 1])
def test_invalid_render_mode_raises(mode: object) -> None:
    with pytest.raises(ValueError, match="render_mode") as excinfo:
        TopDownRenderer(LENGTH, BEAM, mode)  # type: ignore[arg-type]
    message = str(excinfo.value)
    assert repr(mode) in message
    assert "rgb_array" in message and "human" in message


def test_invalid_arguments_raise() -> None:
    with pytest.raises(ValueError, match="ship_length"):
        TopDownRenderer(0.0, BEAM, "rgb_array")
    with pytest.raises(ValueError, match="ship_beam"):
        TopDownRenderer(LENGTH, -1.0, "rgb_array")
    r = TopDownRenderer(LENGTH, BEAM, "rgb_array")
    with pytest.raises(ValueError, match="path"):
        r.draw(0.0, 0.0, 0.0, path=np.zeros((3, 3)))
    r.close()


def test_none_mode_draws_nothing() -> None:
    r = TopDownRenderer(LENGTH, BEAM, None)
    assert r.draw(0.0, 0.0, 0.0, text="x") is None
    r.close()


def test_human_mode_headless_does_not_raise(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("MPLBACKEND", "Agg")
    import matplotlib.pyplot as plt

    previous = matplotlib.get_backend()
    plt.switch_backend("Agg")
    try:
        r = TopDownRenderer(LENGTH, BEAM, "human", width=200, height=200)
        for k in range(3):
            out = r.draw(float(k), 0.0, 0.1 * k, current_speed=0.3, text=f"step {k}")
            assert out is None
        r.close()
    finally:
        plt.switch_backend(previous)


def test_close_and_redraw() -> None:
    r = TopDownRenderer(LENGTH, BEAM, "rgb_array", width=120, height=100)
    first = r.draw(0.0, 0.0, 0.0)
    r.close()
    r.close()  # idempotent
    again = r.draw(0.0, 0.0, 0.0)
    assert first is not None and again is not None
    np.testing.assert_array_equal(first, again)
    r.close()
