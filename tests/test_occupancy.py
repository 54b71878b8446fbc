"""Loading map_server maps: every mode and flag against hand-made PGM/PNG files."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from navseq.errors import NavseqError
from navseq.geometry import Pose2D
from navseq.sim.occupancy import OccupancyGrid, load_map

REPO_MAP = Path(__file__).resolve().parents[1] / "maps" / "turtlebot3_world.yaml"

# One image row of grey levels with their map_server meaning under the default
# thresholds (occupied > 0.65, free < 0.196): p = (255 - v) / 255.
#   255 -> p 0.0 free, 210 -> p 0.176 free, 200 -> p 0.216 between,
#   128 -> p 0.498 between, 89 -> p 0.651 occupied, 0 -> p 1.0 occupied
GREYS = [255, 210, 200, 128, 89, 0]


def write_map(
    folder: Path,
    pixels: np.ndarray | list,
    *,
    image_name: str = "map.pgm",
    pil_mode: str | None = None,
    **settings: object,
) -> Path:
    """A map image (written with Pillow) plus its YAML; returns the YAML path."""
    array = np.asarray(pixels, dtype=np.uint8)
    Image.fromarray(array, mode=pil_mode).save(folder / image_name)
    description = {
        "image": image_name,
        "resolution": 0.1,
        "origin": [0.0, 0.0, 0.0],
        "negate": 0,
        "occupied_thresh": 0.65,
        "free_thresh": 0.196,
    }
    description.update(settings)
    lines = [f"{key}: {value}" for key, value in description.items() if value is not None]
    yaml_path = folder / "map.yaml"
    yaml_path.write_text("\n".join(lines) + "\n")
    return yaml_path


def test_trinary_mode_thresholds_pgm(tmp_path: Path) -> None:
    grid = load_map(write_map(tmp_path, [GREYS]))
    assert grid.data.dtype == np.int8
    assert grid.data.tolist() == [[0, 0, -1, -1, 100, 100]]


def test_trinary_is_the_default_mode(tmp_path: Path) -> None:
    explicit = load_map(write_map(tmp_path, [GREYS], mode="trinary")).data
    implicit = load_map(write_map(tmp_path, [GREYS], mode=None)).data
    assert np.array_equal(explicit, implicit)


def test_negate_swaps_black_and_white(tmp_path: Path) -> None:
    grid = load_map(write_map(tmp_path, [GREYS], negate=1))
    # negated: v' = 255 - v, so black (0) is free and white (255) occupied:
    # 255, 210, 200 -> p 1.0, 0.82, 0.78; 128, 89 -> p 0.50, 0.35; 0 -> p 0.0.
    assert grid.data.tolist() == [[100, 100, 100, -1, -1, 0]]


def test_thresholds_are_read_from_the_yaml(tmp_path: Path) -> None:
    grid = load_map(write_map(tmp_path, [GREYS], occupied_thresh=0.4, free_thresh=0.2))
    # 200 -> p 0.216 is now between, 128 -> p 0.498 now occupied.
    assert grid.data.tolist() == [[0, 0, -1, 100, 100, 100]]


def test_scale_mode_interpolates_between_thresholds(tmp_path: Path) -> None:
    grid = load_map(write_map(tmp_path, [GREYS], mode="scale"))
    values = grid.data.tolist()[0]
    expected_between = [
        int(1 + 98 * ((255 - v) / 255 - 0.196) / (0.65 - 0.196)) for v in (200, 128)
    ]
    assert values == [0, 0, *expected_between, 100, 100]
    assert 0 < expected_between[0] < expected_between[1] < 100


def test_raw_mode_keeps_the_grey_value(tmp_path: Path) -> None:
    grid = load_map(write_map(tmp_path, [[0, 1, 50, 100, 127, 255]], mode="raw"))
    # map_server writes the value into an int8 cell: 255 becomes -1 (unknown).
    assert grid.data.tolist() == [[0, 1, 50, 100, 127, -1]]


def test_raw_mode_with_negate(tmp_path: Path) -> None:
    grid = load_map(write_map(tmp_path, [[255, 205, 0]], mode="raw", negate=1))
    assert grid.data.tolist() == [[0, 50, -1]]


def test_image_is_flipped_so_row_zero_is_the_bottom(tmp_path: Path) -> None:
    # Top image row black (occupied), bottom row white (free).
    grid = load_map(write_map(tmp_path, [[0, 0, 0], [255, 255, 255]]))
    assert grid.data[0].tolist() == [0, 0, 0]
    assert grid.data[1].tolist() == [100, 100, 100]
    assert grid.occupied_mask()[1].all()
    # The world point in the top-left of the picture is occupied.
    row, col = grid.world_to_cell(0.05, 0.15)
    assert grid.data[row, col] == 100


def test_png_rgb_channels_are_averaged(tmp_path: Path) -> None:
    pixels = np.array([[[255, 255, 255], [0, 0, 0], [255, 0, 0], [255, 255, 90]]])
    grid = load_map(write_map(tmp_path, pixels, image_name="map.png"))
    # (255+0+0)/3 = 85 -> p 0.667 occupied; (255+255+90)/3 = 200 -> unknown.
    assert grid.data.tolist() == [[0, 100, 100, -1]]


def test_png_alpha_is_averaged_in_trinary_mode(tmp_path: Path) -> None:
    # White but fully transparent: trinary averages alpha in: (255*3 + 0)/4 = 191.25
    # -> p 0.25, unknown. Opaque white stays free.
    pixels = np.array([[[255, 255, 255, 0], [255, 255, 255, 255]]])
    grid = load_map(write_map(tmp_path, pixels, image_name="map.png"))
    assert grid.data.tolist() == [[-1, 0]]


def test_png_alpha_in_scale_mode_marks_transparent_grey_unknown(tmp_path: Path) -> None:
    grey = 128
    pixels = np.array([[[grey] * 3 + [0], [grey] * 3 + [255], [255, 255, 255, 0], [0, 0, 0, 0]]])
    grid = load_map(write_map(tmp_path, pixels, image_name="map.png", mode="scale"))
    scaled = int(1 + 98 * ((255 - grey) / 255 - 0.196) / (0.65 - 0.196))
    # Transparency only matters between the thresholds; it is not averaged in.
    assert grid.data.tolist() == [[-1, scaled, 0, 100]]


def test_grey_png_with_alpha(tmp_path: Path) -> None:
    pixels = np.array([[[128, 0], [128, 255], [0, 0]]])
    grid = load_map(write_map(tmp_path, pixels, image_name="map.png", pil_mode="LA", mode="scale"))
    assert grid.data[0, 0] == -1
    assert 0 < grid.data[0, 1] < 100
    assert grid.data[0, 2] == 100


def test_palette_png(tmp_path: Path) -> None:
    image = Image.fromarray(np.array([[0, 255, 205]], dtype=np.uint8)).convert("P")
    image.save(tmp_path / "map.png")
    yaml_path = write_map(tmp_path, [[0]], image_name="other.pgm")
    yaml_path.write_text(yaml_path.read_text().replace("other.pgm", "map.png"))
    assert load_map(yaml_path).data.tolist() == [[100, 0, -1]]


def test_origin_resolution_and_yaw(tmp_path: Path) -> None:
    grid = load_map(
        write_map(tmp_path, np.full((4, 6), 255), resolution=0.5, origin=[1.0, 2.0, math.pi / 2])
    )
    assert (grid.width, grid.height) == (6, 4)
    assert grid.resolution == 0.5
    assert grid.origin == Pose2D(1.0, 2.0, math.pi / 2)
    # With a 90 degree origin yaw, grid +x (columns) points along world +y.
    x, y = grid.cell_to_world(0, 2)
    assert (x, y) == pytest.approx((1.0 - 0.25, 2.0 + 1.25))
    assert grid.world_to_cell(x, y) == (0, 2)
    assert grid.contains(0.9, 2.1)
    assert not grid.contains(1.1, 2.1)


def test_world_cell_round_trip_and_bounds() -> None:
    grid = OccupancyGrid(np.zeros((10, 20), np.int8), 0.05, Pose2D(-1.0, -0.5, 0.0))
    assert grid.world_to_cell(-1.0, -0.5) == (0, 0)
    assert grid.world_to_cell(-1.001, -0.5) == (0, -1)
    assert grid.cell_to_world(9, 19) == pytest.approx((-1.0 + 0.975, -0.5 + 0.475))
    assert grid.contains(-0.01, -0.01)
    assert not grid.contains(0.0, 0.0)  # the far edge belongs to the next (missing) cell
    assert grid.bounds == pytest.approx((-1.0, -0.5, 0.0, 0.0))


def test_relative_image_path_resolves_against_the_yaml_folder(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    folder = tmp_path / "maps"
    folder.mkdir()
    write_map(folder, [GREYS])
    monkeypatch.chdir(tmp_path)
    assert load_map(Path("maps/map.yaml")).data.shape == (1, 6)


def test_absolute_image_path(tmp_path: Path) -> None:
    yaml_path = write_map(tmp_path, [GREYS])
    yaml_path.write_text(yaml_path.read_text().replace("map.pgm", str(tmp_path / "map.pgm")))
    assert load_map(yaml_path).data.shape == (1, 6)


def test_missing_image_file(tmp_path: Path) -> None:
    yaml_path = write_map(tmp_path, [GREYS])
    (tmp_path / "map.pgm").unlink()
    with pytest.raises(NavseqError, match="does not exist") as caught:
        load_map(yaml_path)
    assert caught.value.source == f"{yaml_path}:1"  # the line that names the image
    assert "map.pgm" in str(caught.value)


def test_yaml_without_image_key(tmp_path: Path) -> None:
    yaml_path = tmp_path / "map.yaml"
    yaml_path.write_text("resolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(NavseqError, match="no 'image'"):
        load_map(yaml_path)


def test_yaml_without_resolution(tmp_path: Path) -> None:
    with pytest.raises(NavseqError, match="no 'resolution'") as caught:
        load_map(write_map(tmp_path, [GREYS], resolution=None))
    assert caught.value.subject == "key resolution"


@pytest.mark.parametrize(
    ("settings", "key"),
    [
        ({"resolution": -0.05}, "resolution"),
        ({"resolution": "fine"}, "resolution"),
        ({"origin": [0, 0]}, "origin"),
        ({"origin": "[a, b, c]"}, "origin"),
        ({"negate": 2}, "negate"),
        ({"occupied_thresh": 1.5}, "occupied_thresh"),
        ({"free_thresh": -0.1}, "free_thresh"),
        ({"free_thresh": "low"}, "free_thresh"),
        ({"free_thresh": 0.7, "occupied_thresh": 0.6}, "free_thresh"),
        ({"mode": "fuzzy"}, "mode"),
    ],
)
def test_bad_settings_name_the_key(tmp_path: Path, settings: dict, key: str) -> None:
    yaml_path = write_map(tmp_path, [GREYS], **settings)
    with pytest.raises(NavseqError) as caught:
        load_map(yaml_path)
    assert caught.value.subject == f"key {key}"
    assert str(yaml_path) in str(caught.value)


def test_missing_thresholds_default_to_map_saver_values(tmp_path: Path) -> None:
    grid = load_map(write_map(tmp_path, [GREYS], occupied_thresh=None, free_thresh=None))
    assert grid.data.tolist() == [[0, 0, -1, -1, 100, 100]]


def test_corrupt_image(tmp_path: Path) -> None:
    yaml_path = write_map(tmp_path, [GREYS])
    (tmp_path / "map.pgm").write_bytes(b"P5\n6 1\n255\n\x00")  # header promises 6 bytes
    with pytest.raises(NavseqError, match="cannot read the map image"):
        load_map(yaml_path)
    (tmp_path / "map.pgm").write_text("this is not an image")
    with pytest.raises(NavseqError, match="cannot read the map image"):
        load_map(yaml_path)


def test_missing_yaml_and_bad_yaml(tmp_path: Path) -> None:
    with pytest.raises(NavseqError, match="not found"):
        load_map(tmp_path / "nowhere.yaml")
    broken = tmp_path / "broken.yaml"
    broken.write_text("image: map.pgm\nresolution: [0.05\n")
    with pytest.raises(NavseqError, match="not valid YAML"):
        load_map(broken)
    listing = tmp_path / "list.yaml"
    listing.write_text("- 1\n- 2\n")
    with pytest.raises(NavseqError, match="mapping"):
        load_map(listing)


def test_turtlebot3_world_map() -> None:
    grid = load_map(REPO_MAP)
    assert (grid.width, grid.height) == (384, 384)
    assert grid.resolution == pytest.approx(0.05)
    assert grid.origin == Pose2D(-10.0, -10.0, 0.0)
    assert grid.source == str(REPO_MAP)
    # The centre pillar of the 3 x 3 grid is a wall outline around an unseen inside;
    # the floor between pillars is free; the far corner of the image is unknown.
    assert grid.data[grid.world_to_cell(0.0, 0.0)] == -1
    assert grid.data[grid.world_to_cell(0.2, 0.0)] == 100
    assert grid.data[grid.world_to_cell(0.55, 0.55)] == 0
    assert grid.data[grid.world_to_cell(-9.9, -9.9)] == -1


REQUIRED = ("image", "resolution", "origin")
WRONG_TYPES = {
    "image": ["null", "5", "[map.pgm]", "{file: map.pgm}", "''", "true"],
    "resolution": ["null", "fine", "[0.05]", "{m: 0.05}", "true", ".nan", ".inf", "0"],
    "origin": [
        *("null", "0", "[0, 0]", "[0, 0, 0, 0]", "'[0, 0, 0]'", "{x: 0, y: 0, yaw: 0}"),
        *("[a, 0, 0]", "[true, 0, 0]", "[[0], 0, 0]", "[.nan, 0, 0]"),
    ],
    "negate": ["null", "2", "0.5", "[0]", "{a: 0}", "off please"],
    "occupied_thresh": ["null", "high", "[0.65]", "true", "2"],
    "free_thresh": ["null", "low", "{a: 1}", "false", "-1"],
    "mode": ["null", "5", "[trinary]", "{a: 1}", "fuzzy"],
}


def _map_yaml_with(tmp_path: Path, key: str, value: str | None) -> Path:
    """A valid map's YAML with ``key`` set to ``value`` (written as is), or left out."""
    yaml_path = write_map(tmp_path, [GREYS])
    lines = [line for line in yaml_path.read_text().splitlines() if not line.startswith(key)]
    if value is not None:
        lines.append(f"{key}: {value}")
    yaml_path.write_text("\n".join(lines) + "\n")
    return yaml_path


@pytest.mark.parametrize("key", REQUIRED)
def test_every_required_map_setting_missing_is_refused_naming_the_file_and_key(
    tmp_path: Path, key: str
) -> None:
    yaml_path = _map_yaml_with(tmp_path, key, None)
    with pytest.raises(NavseqError, match=f"the map YAML has no '{key}'") as caught:
        load_map(yaml_path)
    assert caught.value.subject == f"key {key}"
    assert str(caught.value).startswith(str(yaml_path))


@pytest.mark.parametrize(
    ("key", "value"), [(key, value) for key, values in WRONG_TYPES.items() for value in values]
)
def test_every_map_setting_of_the_wrong_type_is_refused_naming_its_line_and_key(
    tmp_path: Path, key: str, value: str
) -> None:
    yaml_path = _map_yaml_with(tmp_path, key, value)
    line = yaml_path.read_text().splitlines().index(f"{key}: {value}") + 1
    with pytest.raises(NavseqError) as caught:
        load_map(yaml_path)
    assert caught.value.subject == f"key {key}"
    assert caught.value.source == f"{yaml_path}:{line}"


def test_a_map_without_origin_is_refused_by_the_cli_with_exit_2(tmp_path: Path) -> None:
    from cli_support import assert_clean_error, navseq, write_mission

    yaml_path = _map_yaml_with(tmp_path, "origin", None)
    mission = write_mission(tmp_path / "m.yaml", "  - [0.05, 0.05]\n")
    for command in ("validate", "run"):
        result = navseq(command, mission, "--map", yaml_path, cwd=tmp_path, timeout=60)
        assert_clean_error(result)
        assert f"{yaml_path}:1, key origin: the map YAML has no 'origin'" in result.stderr
