"""Checker.verify / verify_file / diagnose and read_depth_map against `zcheck export` + `zcheck verify`."""
import json
import pickle

import numpy as np
import pytest

import zcheck
from helpers import H, W, assert_documents_equal, run_cli, without_timings


def consistent_names(hypotheses):
    return [h["hypothesis"] for h in hypotheses if h["consistent"]]


def test_ray_render_verifies_and_its_flip_does_not(default_checker, small_camera):
    z = default_checker.render(small_camera, "eye-z")
    report = default_checker.verify(small_camera, z, "eye-z")
    assert report.consistent and report.unexplained == 0 and report.both_hit > 0.5 * W * H
    doc = report.to_dict()
    assert doc["depth_map"] == {"file": "<array>", "quantity": "eye-z", "channel": "", "scale": None, "offset": 0.0,
                                "miss": None, "declared": {"quantum": 0.0, "rel_tolerance": 0.0, "abs_tolerance": 0.0,
                                                           "noise_model": None, "allow_holes": False}}
    assert "diagnosis" not in doc

    flipped = z[::-1]
    bad = default_checker.verify(small_camera, flipped, "eye-z")
    assert not bad.consistent and bad.unexplained > 1000 and bad.diagnosis == []
    hypotheses = default_checker.diagnose(small_camera, flipped, "eye-z")
    assert consistent_names(hypotheses)[0] == "y-flip"
    assert set(hypotheses[0]) == {"hypothesis", "variant", "explanation", "consistent", "unexplained",
                                  "unexplained_estimated", "fitted", "consistent_except_edges",
                                  "unexplained_at_edges"}
    diagnosed = default_checker.verify(small_camera, flipped, "eye-z", diagnose=True)
    assert diagnosed.diagnosis == hypotheses
    # (the JSON's explanations can differ in spacing: prettyJson folds "[-1,1]" inside strings too)
    squeeze = lambda hs: [{**h, "explanation": h["explanation"].replace(" ", "")} for h in hs]
    assert squeeze(diagnosed.to_dict()["diagnosis"]) == squeeze(hypotheses)
    assert diagnosed.summary().rstrip().endswith("diagnosis  " + next(h["explanation"] for h in hypotheses
                                                                           if h["consistent"]))
    # the unflipped map needs no diagnosis, even when asked for one
    assert default_checker.verify(small_camera, z, "eye-z", diagnose=True).diagnosis == []


def test_every_quantity_round_trips_and_the_wrong_one_is_named(default_checker, small_camera):
    for quantity in zcheck.depth_quantities:
        values = default_checker.render(small_camera, quantity)
        assert default_checker.verify(small_camera, values, quantity).consistent, quantity
    distance = default_checker.render(small_camera, "distance")
    assert not default_checker.verify(small_camera, distance, "eye-z").consistent
    assert "distance-as-eye-z" in consistent_names(default_checker.diagnose(small_camera, distance, "eye-z"))


def test_map_dtypes_miss_and_scale(default_checker, small_camera):
    z = default_checker.render(small_camera, "eye-z", dtype=np.float64)
    hit = np.isfinite(z)
    # millimetres as uint16, 0 = miss, as a 16-bit PNG holds them
    mm = np.where(hit, np.round(z * 1000), 0).astype(np.uint16)
    report = default_checker.verify(small_camera, mm, "eye-z", scale=1000)
    assert report.consistent and report.both_hit == hit.sum()
    assert report.to_dict()["depth_map"]["scale"] == 1000
    # a renderer's own "no surface" value
    assert default_checker.verify(small_camera, np.where(hit, z, -7.0), "eye-z", miss=-7.0).consistent
    assert default_checker.verify(small_camera, np.where(hit, z, 0.0), "eye-z").consistent  # <= 0 is a miss
    far = np.where(hit, z, 1e9)
    assert not default_checker.verify(small_camera, far, "eye-z").consistent  # a surface at 1e9 that is not there
    assert default_checker.verify(small_camera, far, "eye-z", miss=1e9).consistent
    # the same map in metres with a scale: stored = depth x scale
    assert default_checker.verify(small_camera, z * 4, "eye-z", scale=4).consistent
    # a float map off by 1 mm is not within float32 tolerance
    assert not default_checker.verify(small_camera, z + 1e-3, "eye-z").consistent


@pytest.mark.parametrize("suffix,exported,read_as", [("pfm", "eye-z", "eye-z"), ("exr", "eye-z", "eye-z"),
                                                     ("exr", "distance", "eye-z"), ("tif", "window", "window")])
def test_cli_export_then_python_verify_matches_cli_verify(tmp_path, default_checker, small_camera, small_camera_file,
                                                          suffix, exported, read_as):
    path = tmp_path / f"depth.{suffix}"
    run_cli("export", "--camera", small_camera_file, "--quantity", exported, "-o", path, check_rc=0)
    rc, out, _ = run_cli("verify", "--camera", small_camera_file, "--depth-map", path, "--quantity", read_as,
                         "--diagnose", "--json")
    cli = json.loads(out)
    assert rc == (0 if cli["consistent"] else 1)
    assert cli["consistent"] is (exported == read_as)

    # the file holds exactly what render() returns (float32, row 0 at the top)
    values = zcheck.read_depth_map(str(path), small_camera, quantity=exported)
    assert values.shape == (H, W) and values.dtype == np.float64
    assert np.array_equal(values, default_checker.render(small_camera, exported).astype(np.float64))

    # read_depth_map + verify: the same verdict and counts
    report = default_checker.verify(small_camera, values, read_as, diagnose=True)
    assert report.consistent is cli["consistent"]
    assert report.to_dict()["pixels"] == cli["pixels"]
    if not report.consistent:
        assert consistent_names(report.diagnosis) == consistent_names(cli["diagnosis"])

    # verify_file: the command's whole document but for the timings
    from_file = default_checker.verify_file(small_camera, str(path), read_as, diagnose=True)
    assert_documents_equal(without_timings(from_file.to_dict()), without_timings(cli))


def test_png_millimetres_match_the_cli(tmp_path, default_checker, small_camera, small_camera_file):
    path = tmp_path / "depth_mm.png"
    run_cli("export", "--camera", small_camera_file, "--quantity", "eye-z", "--scale", 1000, "-o", path, check_rc=0)
    _, out, _ = run_cli("verify", "--camera", small_camera_file, "--depth-map", path, "--quantity", "eye-z",
                        "--scale", 1000, "--json", check_rc=0)
    from_file = default_checker.verify_file(small_camera, str(path), "eye-z", scale=1000)
    assert_documents_equal(without_timings(from_file.to_dict()), without_timings(json.loads(out)))
    values = zcheck.read_depth_map(str(path), small_camera, scale=1000)
    z = default_checker.render(small_camera, "eye-z", dtype=np.float64)
    assert np.array_equal(np.isnan(values), np.isinf(z))
    assert np.allclose(values[np.isfinite(z)], z[np.isfinite(z)], rtol=0, atol=0.5e-3 + 1e-12)
    with pytest.raises(zcheck.Error) as caught:
        zcheck.read_depth_map(str(path), small_camera)
    rc, _, err = run_cli("verify", "--camera", small_camera_file, "--depth-map", path, "--quantity", "eye-z")
    assert rc == 2 and err.strip() == "zcheck: error: " + str(caught.value)


def test_read_depth_map_channels(tmp_path, default_checker, small_camera, small_camera_file):
    path = tmp_path / "both.exr"
    run_cli("export", "--camera", small_camera_file, "--quantity", "eye-z,distance", "-o", path, check_rc=0)
    z = zcheck.read_depth_map(str(path), small_camera, quantity="eye-z")
    d = zcheck.read_depth_map(str(path), small_camera, channel="distance")
    assert np.array_equal(z, default_checker.render(small_camera, "eye-z").astype(np.float64))
    assert np.array_equal(d, default_checker.render(small_camera, "distance").astype(np.float64))
    with pytest.raises(zcheck.Error, match="has no channel 'depth'"):
        zcheck.read_depth_map(str(path), small_camera, channel="depth")
    with pytest.raises(zcheck.Error, match="160x120|160|120"):
        zcheck.read_depth_map(str(path), small_camera.replace(width=80))


def write_pfm(path, image):
    """A 1-channel little-endian PFM (rows stored bottom to top, as the format says)."""
    height, width = image.shape
    with open(path, "wb") as f:
        f.write(f"Pf\n{width} {height}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(image[::-1], dtype="<f4").tobytes())


def test_regression_verify_scale_on_a_float_map_kept_the_integer_quantum(tmp_path, default_checker, small_camera,
                                                                          small_camera_file):
    """`verify --scale 1000` on a float map in millimetres took 1/scale (1 mm) as the storage
    step, as for a 16-bit PNG, and so accepted errors a thousand times the float's own step."""
    eye_z = default_checker.render(small_camera, "eye-z", route="raster").astype(np.float64)
    millimetres = np.where(np.isfinite(eye_z), eye_z * 1000.0, np.inf)
    good, bad = tmp_path / "good.pfm", tmp_path / "bad.pfm"
    write_pfm(good, millimetres)
    # 0.25 mm too far everywhere: far beyond binary32's step (~1e-3 mm at these depths), within 1 mm.
    write_pfm(bad, np.where(np.isfinite(millimetres), millimetres + 0.25, np.inf))
    args = ("verify", "--camera", small_camera_file, "--quantity", "eye-z", "--scale", "1000", "--depth-map")
    assert run_cli(*args, good)[0] == 0
    assert run_cli(*args, bad)[0] == 1
    # The module's file reader takes the same quantum.
    assert default_checker.verify_file(small_camera, str(good), "eye-z", scale=1000).consistent
    assert not default_checker.verify_file(small_camera, str(bad), "eye-z", scale=1000).consistent


def test_miss_rules_offset_and_channels(tmp_path, default_checker, small_camera, small_camera_file):
    z = default_checker.render(small_camera, "eye-z", dtype=np.float64)
    hit = np.isfinite(z)
    # "no surface" as 1e10, matched by a comparison
    far = np.where(hit, z, 1e10)
    report = default_checker.verify(small_camera, far, "eye-z", miss=">=1e9")
    assert report.consistent and report.to_dict()["depth_map"]["miss"] == ">=1e9"
    # a depth-buffer dump where 0 is a real value and 65535 the miss: miss= replaces integer 0
    mm = np.where(hit, np.round(z * 1000), 65535).astype(np.uint16)
    assert default_checker.verify(small_camera, mm, "eye-z", scale=1000, miss=65535).consistent
    assert not default_checker.verify(small_camera, mm, "eye-z", scale=1000).consistent
    # depth = stored / scale + offset
    assert default_checker.verify(small_camera, z - 0.5, "eye-z", offset=0.5).consistent
    assert default_checker.verify(small_camera, (z - 0.5) * 4, "eye-z", scale=4, offset=0.5).consistent
    with pytest.raises(zcheck.Error, match="miss value 'abc' is neither a number"):
        default_checker.verify(small_camera, z, "eye-z", miss="abc")
    with pytest.raises(zcheck.Error, match="offset must be a finite number"):
        default_checker.verify(small_camera, z, "eye-z", offset=float("inf"))
    # files: several channels named as depth need the quantity or a channel
    path = tmp_path / "both.exr"
    run_cli("export", "--camera", small_camera_file, "--quantity", "eye-z,distance", "-o", path, check_rc=0)
    with pytest.raises(zcheck.Error, match=r"several of its channels are named as depth \('Z', 'distance'\)"):
        zcheck.read_depth_map(str(path), small_camera)
    assert default_checker.verify_file(small_camera, str(path), "eye-z").to_dict()["depth_map"]["channel"] == "Z"
    wrong = default_checker.verify_file(small_camera, str(path), "eye-z", channel="distance")
    assert not wrong.consistent and wrong.to_dict()["depth_map"]["channel"] == "distance"


def test_sidecar_describes_the_file(tmp_path, default_checker, small_camera, small_camera_file):
    # A two-channel EXR whose sidecar names the channel; the keys the options leave open come from it.
    path = tmp_path / "both.exr"
    run_cli("export", "--camera", small_camera_file, "--quantity", "eye-z,distance", "-o", path, check_rc=0)
    sidecar = tmp_path / "both.json"
    sidecar.write_text('{"channel": "distance", "renderer": "ignored"}')
    depth = zcheck.read_depth_map(path, small_camera, sidecar=sidecar)
    assert np.array_equal(np.isfinite(depth), np.isfinite(zcheck.read_depth_map(path, small_camera, channel="distance")))
    assert default_checker.verify_file(small_camera, path, "distance", sidecar=sidecar).consistent
    # the channel argument wins over the sidecar's
    assert default_checker.verify_file(small_camera, path, "eye-z", channel="Z", sidecar=sidecar).consistent
    sidecar.write_text('{"scale": "a thousand"}')
    with pytest.raises(zcheck.Error, match=r"\"scale\" must be a positive finite number"):
        zcheck.read_depth_map(path, small_camera, quantity="eye-z", sidecar=sidecar)


def test_regression_an_explicit_offset_0_lost_to_the_sidecars_offset(tmp_path, default_checker, small_camera,
                                                                      small_camera_file):
    """--offset 0 (offset=0) is given: it wins over a sidecar's offset like any other value."""
    path = tmp_path / "z.exr"
    run_cli("export", "--camera", small_camera_file, "--quantity", "eye-z", "-o", path, check_rc=0)
    sidecar = tmp_path / "side.json"
    sidecar.write_text('{"offset": 0.5}')
    # the sidecar alone shifts the map by 0.5: wrong
    assert not default_checker.verify_file(small_camera, path, "eye-z", sidecar=sidecar).consistent
    for offset in (0, 0.0):
        report = default_checker.verify_file(small_camera, path, "eye-z", sidecar=sidecar, offset=offset)
        assert report.consistent and report.to_dict()["depth_map"]["offset"] == 0
    rc, out, _ = run_cli("verify", "--camera", small_camera_file, "--depth-map", path, "--quantity", "eye-z",
                         "--sidecar", sidecar, "--offset", "0", "--json")
    assert rc == 0 and json.loads(out)["depth_map"]["offset"] == 0
    rc, out, _ = run_cli("verify", "--camera", small_camera_file, "--depth-map", path, "--quantity", "eye-z",
                         "--sidecar", sidecar, "--json")
    assert rc == 1 and json.loads(out)["depth_map"]["offset"] == 0.5


def test_declared_reading_accepts_real_world_maps_and_the_diagnosis_names_the_option(default_checker, small_camera):
    """Issue 36: millimetre-rounded floats (cv2.imread(p, -1) / 1000.0), float16, a miss value, holes."""
    z = default_checker.render(small_camera, "eye-z", dtype="float64")
    hit = np.isfinite(z)
    mm = np.where(hit, np.round(z * 1000) / 1000, np.inf).astype(np.float32)
    assert not default_checker.verify(small_camera, mm, "eye-z").consistent
    assert consistent_names(default_checker.diagnose(small_camera, mm, "eye-z"))[0] == "quantum"
    report = default_checker.verify(small_camera, mm, "eye-z", quantum=0.001)
    assert report.consistent and report.to_dict()["depth_map"]["declared"]["quantum"] == 0.001
    assert default_checker.verify(small_camera, z.astype(np.float16), "eye-z").consistent

    cycles = np.where(hit, z, 1e10)
    best = default_checker.diagnose(small_camera, cycles, "eye-z")[0]
    assert best["consistent"] and best["hypothesis"] == "miss-value" and "--miss '>=1e9'" in best["explanation"]
    assert default_checker.verify(small_camera, cycles, "eye-z", miss=">=1e9").consistent

    holed = z.copy()
    holed[::7, ::5] = np.nan
    assert not default_checker.verify(small_camera, holed, "eye-z").consistent
    allowed = default_checker.verify(small_camera, holed, "eye-z", allow_holes=True)
    assert allowed.consistent and allowed.to_dict()["pixels"]["holes"] > 0.9 * np.isnan(holed[hit]).sum()
    hole = zcheck.pixel_classes.index("hole")
    assert (allowed.pixel_classes == hole).sum() == allowed.to_dict()["pixels"]["holes"]

    # A uniform scale is systematic: no tolerance absorbs it; unbiased errors of its size are an accuracy.
    short = z * (1 - 4e-4)
    refused = default_checker.verify(small_camera, short, "eye-z", rel_tolerance=5e-4)
    assert not refused.consistent and "systematic" in refused.to_dict()["declared_accuracy_refused"]
    jitter = z * (1 + np.random.default_rng(3).uniform(-4e-4, 4e-4, z.shape))
    assert default_checker.verify(small_camera, jitter, "eye-z", rel_tolerance=5e-4).consistent
    assert default_checker.verify(small_camera, jitter, "eye-z", rel_tolerance=5e-4).to_dict()[
        "declared_accuracy_refused"] is None
    assert not default_checker.verify(small_camera, jitter, "eye-z", rel_tolerance=2e-4).consistent


def test_regression_quantum_5_accepted_metres_read_as_millimetres(default_checker, small_camera):
    """nerfstudio's default scale 1000 on a float map in metres, and the --quantum 5 the diagnosis
    used to suggest for it: every keyword declaration goes through the one acceptance rule."""
    z = default_checker.render(small_camera, "eye-z")
    tiny = z / 1000
    for declared in ({"quantum": 5}, {"quantum": 1}, {"abs_tolerance": 5}, {"rel_tolerance": 0.9},
                     {"noise_model": "5+0*z^2"}, {"quantum": 5, "allow_holes": True}):
        report = default_checker.verify(small_camera, tiny, "eye-z", **declared)
        assert not report.consistent, declared
        assert report.to_dict()["declared_accuracy_refused"], declared
    for h in default_checker.diagnose(small_camera, tiny, "eye-z"):
        assert not (h["consistent"] and any(part in h["hypothesis"] for part in ("quantum", "tolerance", "noise")))


def test_noise_model_accepts_a_noisy_map_and_not_its_flip_or_its_scale(default_checker, small_camera):
    z = default_checker.render(small_camera, "eye-z").astype(np.float64)
    sigma = 0.002 + 0.0001 * z ** 2  # a sensor's noise growing with depth (map units)
    noisy = z + sigma * np.random.default_rng(7).standard_normal(z.shape)
    assert not default_checker.verify(small_camera, noisy, "eye-z").consistent
    model = "0.002+0.0001*z^2"
    report = default_checker.verify(small_camera, noisy, "eye-z", noise_model=model)
    assert report.consistent and report.to_dict()["depth_map"]["declared"]["noise_model"] == model
    assert not default_checker.verify(small_camera, noisy[::-1], "eye-z", noise_model=model).consistent
    scaled = default_checker.verify(small_camera, noisy * 1.01, "eye-z", noise_model=model)
    assert not scaled.consistent and "systematic" in scaled.to_dict()["declared_accuracy_refused"]
    # undeclared, the diagnosis answers it with a noise model, first
    best = default_checker.diagnose(small_camera, noisy, "eye-z")[0]
    assert best["consistent"] and best["hypothesis"] == "noise" and "--noise-model '" in best["explanation"]


@pytest.mark.parametrize("call, message", [
    (lambda c, cam, z: c.verify(cam, z), "quantity is required"),
    (lambda c, cam, z: c.verify(cam, z, 3), "quantity must be a string"),
    (lambda c, cam, z: c.verify(cam, z, "eye-z", miss=[0, 65535]), "miss must be a number or a rule"),
    (lambda c, cam, z: c.verify(cam, z, "eye-z", scale="1000"), "scale must be a number, got str"),
    (lambda c, cam, z: c.verify(cam, z, "eye-z", quantum=-1), "quantum must be a finite number >= 0"),
    (lambda c, cam, z: c.verify(cam, z, "eye-z", rel_tolerance=1.5), "rel_tolerance must be a finite number >= 0 and below 1"),
    (lambda c, cam, z: c.verify(cam, z, "eye-z", allow_holes=1), "allow_holes must be True or False"),
    (lambda c, cam, z: c.verify(cam, z, "eye-z", noise_model=0.01), "noise_model must be a string"),
    (lambda c, cam, z: c.verify(cam, z, "eye-z", noise_model="gauss"), "noise_model must be kinect, A+B*z^2"),
    (lambda c, cam, z: c.diagnose(cam, z), "quantity is required"),
])
def test_wrong_arguments_raise_one_line_naming_the_argument(default_checker, small_camera, call, message):
    z = default_checker.render(small_camera, "eye-z")
    with pytest.raises(zcheck.Error) as caught:
        call(default_checker, small_camera, z)
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_regression_pixel_classes_named_only_up_to_raster_only():
    """zcheck.pixel_classes stopped at a hard-coded last class, so a class added after it (hole)
    had an index in Report.pixel_classes but no name."""
    assert zcheck.pixel_classes[-1] == "hole" and len(set(zcheck.pixel_classes)) == len(zcheck.pixel_classes)
    assert {"ray-only", "raster-only", "hole"} <= set(zcheck.pixel_classes)


def test_verify_reports_the_map_in_its_units_and_counts_values_out_of_range(default_checker, small_camera):
    z = default_checker.render(small_camera, "eye-z").astype(np.float64)
    far = z * 1.002  # 0.2 % too far everywhere
    report = default_checker.verify(small_camera, far, "eye-z")
    doc = report.to_dict()
    errors = doc["map_errors"]
    assert errors["quantity"] == "eye-z" and not errors["eye_z_equivalent"]
    assert errors["median_rel"] == pytest.approx(0.002, rel=1e-4) and errors["max_rel"] == pytest.approx(0.002, rel=1e-4)
    worst = errors["worst_pixel"]
    assert worst["map"] == far[worst["row"], worst["col"]]
    assert worst["true"] == pytest.approx(z[worst["row"], worst["col"]], rel=1e-6)
    assert errors["max_abs"] == pytest.approx(np.nanmax(np.where(np.isfinite(z), 0.002 * z, np.nan)), rel=1e-5)
    assert "map_only" in doc["pixels"] and "raster_only" not in doc["pixels"] and report.map_only == report.raster_only
    assert "map - truth (eye-z), in the map's units" in report.summary()
    # a negative eye-z is no miss: counted, named, and the map rejected
    holed = z.copy()
    holed[10:14, 20:30] = -1.0
    bad = default_checker.verify(small_camera, holed, "eye-z")
    assert not bad.consistent and bad.out_of_range == 40
    assert bad.to_dict()["out_of_range"]["first"] == {"col": 20, "row": 10, "stored": -1.0}
    with pytest.raises(zcheck.Error, match="it holds no eye-z depth"):
        default_checker.verify(small_camera, np.full_like(z, -2.0), "eye-z")


def test_regression_a_correct_map_of_a_mesh_in_utm_coordinates_was_judged_against_its_binary32_rounding():
    """A wall at northing 4212345.321, 10 m before an OpenCV camera looking north: every pixel's
    eye-z is 10 for the file's digits (a renderer in binary64, or one drawing around a local
    origin), and 4212345.5 − 4212335.321 = 10.179 for the wall as binary32 holds it at the file's
    coordinates (a GPU fed those floats). zcheck traced the second and called the correct map
    INCONSISTENT. It now holds the wall about a local origin, as large-world renderers do: the
    correct map is CONSISTENT, the rounded one is not, and the report says what binary32 at the
    file's coordinates does (the move, the coordinates and its step there)."""
    x0, y, z0 = 512345.678, 4212345.321, 123.4
    vertices = np.array([[x0 - 30, y, z0 - 30], [x0 + 30, y, z0 - 30], [x0 + 30, y, z0 + 30], [x0 - 30, y, z0 + 30]])
    scene = zcheck.Scene.from_arrays(vertices, [[0, 1, 2], [0, 2, 3]], name="utm wall")
    # The box's centre (512345.678, 4212345.321, 123.4) on the grid of 64 (the power of two at or
    # below its diagonal, 84.9): the vertices are held about it, in the world where they were.
    assert scene.origin.tolist() == [512320.0, 4212352.0, 128.0]
    assert np.abs(scene.vertices + scene.origin - vertices).max() < 1e-5
    assert np.abs(scene.bounds[0] - vertices.min(axis=0)).max() < 1e-5
    # OpenCV camera at (x0, y − 10, z0): x east, y down (−up), z north.
    world_from_eye = np.array([[1, 0, 0, x0], [0, 0, 1, y - 10], [0, -1, 0, z0], [0, 0, 0, 1]], dtype=float)
    camera = zcheck.Camera.from_dict({
        "convention": "opencv", "image": {"width": 32, "height": 24},
        "view": {"world_from_eye": world_from_eye.ravel().tolist(), "layout": "row-major", "vectors": "column"},
        "projection": {"type": "pinhole", "fx": 20, "fy": 20, "cx": 15.5, "cy": 11.5, "near": 1, "far": 100}})
    checker = zcheck.Checker(scene)
    # Both routes see the file's wall: eye-z 10 at every pixel, to binary64 rounding at 4.2e6.
    traced = checker.render(camera, "eye-z", route="ray")
    drawn = checker.render(camera, "eye-z", route="raster")
    assert np.abs(traced - 10.0).max() < 1e-6
    assert np.abs(drawn - 10.0).max() < 1e-4  # unorm24 at far/near 100
    assert checker.check(camera).consistent
    # World positions are the world's: the wall's northing at every pixel.
    world = checker.render(camera, "position-world", route="ray", dtype="float64")
    assert np.abs(world[..., 1] - y).max() < 1e-6
    stored_wall = float(np.float32(y)) - (y - 10)
    assert abs(stored_wall - 10.179) < 1e-9
    for depth, consistent in ((10.0, True), (stored_wall, False)):
        report = checker.verify(camera, np.full((24, 32), depth, dtype=np.float32), "eye-z")
        assert report.consistent == consistent, depth
        warnings = [w for w in report.to_dict()["warnings"] if "binary32" in w]
        assert len(warnings) == 1, report.to_dict()["warnings"]
        assert warnings[0].startswith("mesh 'utm wall': far from the origin, held about (512320, 4212352, 128)")
        assert "its vertices moved by up to 0.1793" in warnings[0]
        assert "where binary32 steps by 0.5" in warnings[0]
        assert "binary32" in report.summary()
    # A pickled scene (worker processes) keeps its origin and what its arrays lost: the same verdict and note.
    copy = pickle.loads(pickle.dumps(scene))
    assert copy.origin.tolist() == scene.origin.tolist()
    unpickled = zcheck.Checker(copy).verify(camera, np.full((24, 32), 10.0, dtype=np.float32), "eye-z")
    assert unpickled.consistent
    assert [w for w in unpickled.to_dict()["warnings"] if "binary32" in w] == [
        w for w in checker.verify(camera, np.full((24, 32), 10.0, dtype=np.float32), "eye-z").to_dict()["warnings"]
        if "binary32" in w]
    # A tampered pickle's origin is refused, named.
    state = list(scene.__getstate__())
    state[5] = (float("nan"), 0.0, 0.0)
    with pytest.raises(zcheck.Error, match=r"a pickled Scene: its origin \(nan, 0, 0\) is not a point within 1e15"):
        zcheck.Scene.__new__(zcheck.Scene).__setstate__(tuple(state))
    # The same wall 100 m from the origin: no word, and held where it is.
    near = zcheck.Scene.from_arrays(vertices - [x0 - 100, y - 100, z0], [[0, 1, 2], [0, 2, 3]], name="near wall")
    assert near.origin.tolist() == [0.0, 0.0, 0.0]
    assert not [w for w in zcheck.Checker(near).check(near.default_camera.replace(width=32, height=24)).to_dict()["warnings"]
                if "binary32" in w]
