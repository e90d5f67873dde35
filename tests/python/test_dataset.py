"""Datasets as one job: `zcheck dataset verify/report/import` over generated datasets in every
format (dataset_maker.py), copies broken the way datasets break, shards and resumed runs.

Each broken frame must be flagged, and named by the diagnosis, and no other frame may be."""
import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest

import zcheck

from dataset_maker import DatasetMaker, FRAMES, has
from helpers import MODELS, run_cli

BUNNY = MODELS / "stanford-bunny.obj"
pytestmark = pytest.mark.skipif(not BUNNY.exists(), reason="the shared models are not beside the repository")

# How the broken copies break, and the name the diagnosis must give each frame.
BROKEN_TRANSFORMS = {3: "y-flip", 7: "inverted-extrinsic", 11: "opencv-axes", 15: "distance", 19: "centimetres"}
EXPECTED_NAME = {"y-flip": "y-flip", "inverted-extrinsic": "inverted-extrinsic", "opencv-axes": "opencv-opengl-axes",
                 "distance": "distance-as-eye-z", "centimetres": "depth-scale"}
MISSING_DEPTH = 21
BROKEN_PRINCIPAL_POINT = (5, 13)
BROKEN_MANIFEST_LINE = 9


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    m = DatasetMaker(tmp_path_factory.mktemp("datasets"), BUNNY)
    paths = {
        "colmap_text": m.colmap_text("colmap_text"),
        "colmap_depth": m.colmap_depth_maps("colmap_depth"),
        "transforms": m.transforms(),
        "broken_transforms": m.transforms("broken.json", broken=BROKEN_TRANSFORMS, missing=(MISSING_DEPTH,)),
        "broken_colmap": m.colmap_text("colmap_broken", broken_cx=BROKEN_PRINCIPAL_POINT),
        "gltf": m.gltf_with_cameras(),
    }
    paths["manifest"] = m.manifest("manifest.jsonl", paths["colmap_text"], paths["transforms"], paths["gltf"])
    paths["broken_manifest"] = m.manifest("broken_manifest.jsonl", paths["colmap_text"], paths["transforms"], paths["gltf"],
                                          broken_lines=(BROKEN_MANIFEST_LINE,))
    if has("colmap"):
        paths["colmap_bin"] = m.colmap_convert(paths["colmap_text"], "colmap_bin", "BIN")
        paths["colmap_rewritten"] = m.colmap_convert(paths["colmap_bin"], "colmap_rewritten", "TXT")
    return m, paths


def verify(made, source, *extra, rc=None, results=None):
    m, _ = made
    results = results or m.root / f"results_{Path(str(source)).name}_{len(extra)}.jsonl"
    if Path(results).exists():
        Path(results).unlink()
    code, out, err = run_cli("dataset", "verify", source, "--scene", BUNNY, "--quantity", "eye-z", "-o", results, *extra)
    if rc is not None:
        assert code == rc, f"rc {code}\n{out}\n{err}"
    records = [json.loads(line) for line in Path(results).read_text().splitlines()] if Path(results).exists() else []
    return code, records, out, err


def failing(records):
    return {r["index"]: r for r in records if not r["consistent"]}


def test_every_format_of_a_correct_dataset_is_consistent(made):
    m, p = made
    colmap_depth = str(p["colmap_depth"]) + "/{name}.geometric.bin"
    sources = [(p["colmap_text"], ["--depth", colmap_depth]), (p["transforms"], []), (p["manifest"], [])]
    if "colmap_bin" in p:  # COLMAP's own binary and text writers
        sources += [(p["colmap_bin"], ["--depth", colmap_depth]), (p["colmap_rewritten"], ["--depth", colmap_depth])]
    for source, extra in sources:
        code, records, out, err = verify(made, source, *extra)
        assert code == 0, f"{source}: {out}{err}"
        assert len(records) == FRAMES
        assert sorted(r["index"] for r in records) == list(range(FRAMES))
        assert all(r["consistent"] and r["error"] is None for r in records), source


def test_broken_transforms_flags_exactly_the_broken_frames_and_names_them(made):
    _, p = made
    code, records, out, _ = verify(made, p["broken_transforms"], "--diagnose", rc=1)
    bad = failing(records)
    assert set(bad) == set(BROKEN_TRANSFORMS) | {MISSING_DEPTH}, out
    for index, how in BROKEN_TRANSFORMS.items():
        names = [h["hypothesis"] for h in bad[index]["diagnosis"]]
        assert names and names[0] == EXPECTED_NAME[how], (index, how, names)
    assert "No such file" in bad[MISSING_DEPTH]["error"] and "frame_021.png" in bad[MISSING_DEPTH]["error"]
    # the centimetre PNG: the fitted scale says by how much (values 10x too small; the map is
    # rounded to whole centimetres on ~0.3 m, so the fit is good to a few per cent)
    scale = [v for v in bad[19]["diagnosis"][0]["fitted"] if v["name"] == "value_scale"]
    assert scale and abs(scale[0]["value"] - 0.1) < 0.003


def test_cameras_one_frame_behind_the_maps_are_named_per_frame_and_once_for_the_dataset(made):
    m, _ = made
    # frame i's entry lists frame i-1's camera (frame 0 its own): the map of frame i matches the
    # camera listed for frame i+1; the last map's camera is listed nowhere.
    path = m.transforms("shifted.json", camera_of=lambda i: max(i - 1, 0))
    code, records, out, _ = verify(made, path, "--diagnose", rc=1)
    bad = failing(records)
    assert set(bad) == set(range(1, FRAMES)), out
    for i in range(1, FRAMES - 1):
        first = bad[i]["diagnosis"][0]
        assert first["hypothesis"] == "next-frame-camera" and first["consistent"], (i, first)
        assert f"'{records_by_index(records)[i + 1]['frame']}''s camera" in first["explanation"], first
        assert [v["value"] for v in first["fitted"] if v["name"] == "camera_frame_offset"] == [1.0]
    assert not any(h["hypothesis"].endswith("frame-camera") for h in bad[FRAMES - 1].get("diagnosis", []))
    assert f"{FRAMES - 2} of {FRAMES} frames consistent with the next frame's camera (next-frame-camera)" in out, out


def test_regression_cameras_one_frame_behind_the_maps_of_a_small_object_went_unnamed(tmp_path):
    # Seen from 25 times its size, the bunny covers ~0.15 % of each image and lies between the
    # 16 x 16 grid of single rays that tries another frame's camera before verifying against it:
    # a grid that met no surface ruled every camera out, and the frames paired wrongly went
    # unnamed. (Found through `diagnose` by a random run; the dataset shares the probe.)
    m = DatasetMaker(tmp_path, BUNNY, frames=8, orbit=25)
    path = m.transforms("shifted.json", camera_of=lambda i: max(i - 1, 0))
    hits = [np.count_nonzero(np.isfinite(m.eye_z(i))) for i in range(8)]
    assert max(hits) < 0.003 * m.trajectory.width * m.trajectory.height and min(hits) > 50, hits
    code, records, out, _ = verify((m, None), path, "--diagnose", rc=1)
    bad = failing(records)
    assert set(bad) == set(range(1, 8)), out
    for i in range(1, 7):
        diagnosis = bad[i].get("diagnosis") or [{}]
        assert diagnosis[0].get("hypothesis") == "next-frame-camera" and diagnosis[0]["consistent"], (i, diagnosis[:2])


def test_shuffled_cameras_are_each_matched_with_the_frame_whose_camera_made_the_map(made):
    m, _ = made
    order = list(np.random.default_rng(4).permutation(FRAMES))
    path = m.transforms("shuffled.json", camera_of=lambda i: int(order[i]))
    code, records, out, _ = verify(made, path, "--diagnose", rc=1)
    bad = failing(records)
    assert set(bad) == {i for i in range(FRAMES) if order[i] != i}, out
    for i, r in bad.items():
        first = r["diagnosis"][0]
        listed_at = order.index(i)  # the frame whose entry lists frame i's camera
        offset = [v["value"] for v in first["fitted"] if v["name"] == "camera_frame_offset"]
        assert first["consistent"] and first["hypothesis"].endswith("frame-camera") or \
            first["hypothesis"].startswith("camera-2-frames"), (i, first)
        assert offset == [float(listed_at - i)], (i, listed_at, first)


def test_float_metres_under_nerfstudio_s_default_scale_say_what_to_type(made):
    m, _ = made
    path = m.transforms("float_metres.json", float_npy=True)
    code, records, out, _ = verify(made, path, "--diagnose", rc=1)
    assert len(failing(records)) == FRAMES
    # the default is said in the summary, once, with its count
    assert f"note       depth files hold millimetres, nerfstudio's default (depth_unit_scale_factor 1e-3): scale 1000; " \
           f"--scale replaces it ({FRAMES} of {FRAMES} frames)" in out, out
    for r in records:
        first = r["diagnosis"][0]
        assert first["hypothesis"] == "implied-scale-on-float" and "pass --scale 1" in first["explanation"], first
    assert f"{FRAMES} of {FRAMES} frames consistent read as stored" in out, out
    # and typing it makes every frame consistent
    code, records, out, _ = verify(made, path, "--scale", "1", rc=0)
    assert all(r["consistent"] for r in records)


def records_by_index(records):
    return {r["index"]: r for r in records}


def test_an_opencv_principal_point_in_colmap_coordinates_is_half_a_pixel(made):
    _, p = made
    code, records, _, _ = verify(made, p["broken_colmap"], "--depth", str(p["colmap_depth"]) + "/{name}.geometric.bin",
                                 "--diagnose", rc=1)
    bad = failing(records)
    assert set(bad) == set(BROKEN_PRINCIPAL_POINT)
    for r in bad.values():
        assert r["diagnosis"][0]["hypothesis"] == "half-pixel"


def test_a_malformed_manifest_line_is_that_frame_s_error_and_the_run_goes_on(made):
    _, p = made
    code, records, _, _ = verify(made, p["broken_manifest"], rc=1)
    bad = failing(records)
    assert set(bad) == {BROKEN_MANIFEST_LINE}
    assert "is not valid JSON" in bad[BROKEN_MANIFEST_LINE]["error"]
    assert bad[BROKEN_MANIFEST_LINE]["frame"] == f"line {BROKEN_MANIFEST_LINE + 1}"
    assert len(records) == FRAMES


def test_shards_and_a_resumed_run_give_the_single_run_s_summary(made):
    m, p = made
    source = p["broken_transforms"]
    single = m.root / "single.jsonl"
    verify(made, source, "--diagnose", results=single)
    code, out, err = run_cli("dataset", "report", single, "--json")
    assert code == 1, err
    summary = json.loads(out)
    assert summary["frames"] == FRAMES and summary["inconsistent"] == 5 and summary["errors"] == 1
    assert summary["by_mistake"] == {"y-flip": 1, "inverted-extrinsic": 1, "opencv-opengl-axes": 1, "distance-as-eye-z": 1,
                                     "depth-scale": 1}

    shards = []
    for i in range(3):
        shard = m.root / f"shard{i}.jsonl"
        verify(made, source, "--diagnose", "--shard", f"{i}/3", results=shard)
        shards.append(shard)
    # A killed task: its file cut mid-line, then resumed.
    text = shards[1].read_text()
    lines = text.splitlines(keepends=True)
    shards[1].write_text("".join(lines[:3]) + lines[3][:40])
    code, out, err = run_cli("dataset", "verify", source, "--scene", BUNNY, "--quantity", "eye-z", "--diagnose",
                             "--shard", "1/3", "-o", shards[1], "--resume")
    assert code == 1, err
    resumed = shards[1].read_text().splitlines()
    assert len(resumed) == len(lines) and all(json.loads(line) for line in resumed)
    assert sorted(json.loads(line)["index"] for line in resumed) == list(range(1, FRAMES, 3))
    code, out, err = run_cli("dataset", "report", *shards, "--json")
    assert json.loads(out) == summary


def test_report_finds_missing_and_duplicated_frames(made):
    m, p = made
    a, b = m.root / "a.jsonl", m.root / "b.jsonl"
    verify(made, p["transforms"], "--shard", "0/2", results=a)
    verify(made, p["transforms"], "--shard", "0/4", results=b)
    code, out, err = run_cli("dataset", "report", a, b, "--out", m.root / "partial")
    assert code == 1
    partial = json.loads((m.root / "partial" / "summary.json").read_text())
    assert partial["missing"] == list(range(1, FRAMES, 2))
    assert len(partial["duplicates"]) == len(range(0, FRAMES, 4))
    assert "missing    indices 1 3 5" in out


def test_a_results_file_is_not_overwritten_and_resume_needs_one(made):
    m, p = made
    results = m.root / "kept.jsonl"
    verify(made, p["transforms"], "--shard", "0/8", results=results)
    before = results.read_bytes()
    code, _, err = run_cli("dataset", "verify", p["transforms"], "--scene", BUNNY, "--quantity", "eye-z", "-o", results)
    assert code == 2 and "exists: --resume completes it" in err
    assert results.read_bytes() == before
    code, _, err = run_cli("dataset", "verify", p["transforms"], "--scene", BUNNY, "--quantity", "eye-z", "--resume")
    assert code == 2 and "--resume completes a results file" in err
    # a results file of another dataset is not completed
    code, _, err = run_cli("dataset", "verify", p["manifest"], "--scene", BUNNY, "-o", results, "--resume")
    assert code == 2 and "not this run's" in err


def test_import_writes_the_manifest_a_source_implies(made):
    m, p = made
    manifest = m.root / "imported.jsonl"
    code, out, err = run_cli("dataset", "import", p["transforms"], "-o", manifest)
    assert code == 0, err
    lines = [json.loads(line) for line in manifest.read_text().splitlines()]
    assert len(lines) == FRAMES
    assert lines[0]["camera"] == "transforms.json#images/frame_000.png" and lines[0]["scale"] == 1000
    code, records, _, _ = verify(made, manifest)
    assert code == 0 and len(records) == FRAMES


def test_html_report_has_the_worst_frames_pictures(made):
    m, p = made
    results = m.root / "for_html.jsonl"
    verify(made, p["broken_transforms"], "--diagnose", results=results)
    html = m.root / "html_report" / "report.html"
    code, out, err = run_cli("dataset", "report", results, "--out", m.root / "html_report")
    page = html.read_text()
    # the truth, the map, the heatmap and the classes of the 5 inconsistent frames
    assert page.count("data:image/png;base64,") == 4 * 5
    assert "frame_021.png" in page and "not verified" in page
    assert "<svg" in page


def test_verify_accepts_the_raster_route_s_own_map_at_a_silhouette_sliver(made):
    """Regression: "verify rejected the raster route's own map at a silhouette sliver". At pixel
    (106, 166) of frame 4 the rasterizer's snapped vertices reach over the pixel centre with a
    triangle of the bunny's far side that no ray near the pixel meets and no visible neighbour
    shares a vertex with; `check` explained it, `verify` found no surface for it."""
    m, _ = made
    camera = m.trajectory.camera(4)
    report = m.checker.verify(camera, m.eye_z(4), "eye-z")
    assert report.consistent, report.summary
    assert m.checker.check(camera).consistent


# ---- Python -----------------------------------------------------------------------------------

def _verify_in_worker(frame):
    """A frame verified in another process: everything it needs arrives pickled."""
    camera, _ = frame.load()
    return frame.index, camera, frame.checker().verify_file(camera, frame.depth, frame.quantity, diagnose=True,
                                                            **frame.reading)


def test_python_verify_yields_the_records_the_command_writes(made):
    import zcheck.dataset
    _, p = made
    _, cli, _, _ = verify(made, p["broken_transforms"], "--diagnose")
    records = list(zcheck.dataset.verify(p["broken_transforms"], scene=BUNNY, quantity="eye-z", diagnose=True))
    strip = lambda r: {k: v for k, v in r.items() if k != "seconds"}  # noqa: E731 - wall time differs
    assert sorted(map(lambda r: json.dumps(strip(r), sort_keys=True), records)) == \
        sorted(map(lambda r: json.dumps(strip(r), sort_keys=True), cli))


def test_a_process_pool_over_a_dataset_agrees_with_the_command(made):
    import pickle
    from concurrent.futures import ProcessPoolExecutor
    import zcheck.dataset
    _, p = made
    _, cli, _, _ = verify(made, p["broken_transforms"], "--diagnose")
    by_index = {r["index"]: r for r in cli}
    frames = zcheck.dataset.open(p["broken_transforms"], scene=BUNNY, quantity="eye-z")
    assert len(frames) == FRAMES and frames[3].name == "images/frame_003.png" and frames[3].reading == {"scale": 1000.0}
    usable = [f for f in frames if f.index != MISSING_DEPTH]
    with ProcessPoolExecutor(max_workers=2) as pool:
        for index, camera, report in pool.map(_verify_in_worker, usable):
            record = by_index[index]
            assert report.consistent == record["consistent"], index
            assert report.unexplained == record["unexplained"]["count"], index
            assert report.to_dict()["pixels"] == record["pixels"], index
            if not report.consistent:
                assert report.diagnosis[0]["hypothesis"] == record["diagnosis"][0]["hypothesis"]
            assert camera == pickle.loads(pickle.dumps(camera))
    with pytest.raises(zcheck.Error, match="frame_021.png': No such file"):
        frames[MISSING_DEPTH].load()


def test_camera_scene_and_report_pickle_to_equal_values(made):
    import pickle
    import numpy as np
    m, p = made
    camera = zcheck.Camera.from_file(f"{p['colmap_text']}#frame_007.png", scene=m.scene)
    again = pickle.loads(pickle.dumps(camera))
    assert again == camera and hash(again) == hash(camera) and again.notes == camera.notes
    assert camera != camera.replace(width=321)
    scene = pickle.loads(pickle.dumps(m.scene))
    assert scene.triangle_count == m.scene.triangle_count and scene.name == m.scene.name
    arrays = zcheck.Scene.from_arrays(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]), np.array([[0, 1, 2]]), name="tri")
    assert (pickle.loads(pickle.dumps(arrays)).vertices == arrays.vertices).all()
    flipped = m.eye_z(7)[::-1]
    report = m.checker.verify(m.trajectory.camera(7), flipped, "eye-z", diagnose=True)
    back = pickle.loads(pickle.dumps(report))
    assert back.to_dict() == report.to_dict() and back.summary() == report.summary()
    assert back.unexplained == report.unexplained and not back.consistent
    assert [h["hypothesis"] for h in back.diagnosis] == [h["hypothesis"] for h in report.diagnosis]
    assert (back.error_over_tolerance == report.error_over_tolerance).all()


def test_camera_from_file_reads_every_format_by_reference(made):
    m, p = made
    # The same pose through COLMAP, nerfstudio, OpenCV and glTF: the same projection.
    cameras = [zcheck.Camera.from_file(f"{p['colmap_text']}#frame_007.png", scene=m.scene),
               zcheck.Camera.from_file(f"{p['transforms']}#frame_007", scene=m.scene),
               zcheck.Camera.from_file(str(m.opencv_file(7)), scene=m.scene),
               zcheck.Camera.from_file(f"{p['gltf']}#cam_007", width=320, height=240)]
    world = np.array([0.01, 0.12, 0.02, 1.0])
    pixels = []
    for camera in cameras:
        clip = camera.matrices()["clip_from_world"] @ world
        window = camera.matrices()["window_from_ndc"] @ (clip / clip[3])
        pixels.append((window[0], window[1] if camera.convention != "opengl" else camera.height - window[1]))
    for pixel in pixels[1:]:
        assert np.allclose(pixel, pixels[0], atol=1e-6), pixels
    with pytest.raises(zcheck.Error, match="has no near and far in its file, and there is no scene"):
        zcheck.Camera.from_file(f"{p['colmap_text']}#frame_007.png")
    assert zcheck.Camera.from_file(f"{p['colmap_text']}#3", near=0.1, far=10).width == 320


LOCAL_SLURM = Path(__file__).resolve().parents[1] / "slurm" / "local_slurm.sh"


@pytest.mark.skipif(os.geteuid() != 0 or not has("sbatch") or not has("munged"),
                    reason="a local Slurm (slurm-wlm, munge) is started as root")
def test_a_slurm_job_array_gives_the_single_process_summary(made, tmp_path):
    import subprocess
    from helpers import ZCHECK_EXE
    m, p = made
    source = p["broken_transforms"]
    single = m.root / "for_slurm.jsonl"
    verify(made, source, "--diagnose", results=single)
    run_cli("dataset", "report", single, "--out", tmp_path / "single")
    state = tmp_path / "slurm"
    started = subprocess.run(["bash", LOCAL_SLURM, "start", state], capture_output=True, text=True, timeout=120)
    try:
        assert started.returncode == 0, started.stderr
        env = {**os.environ, "SLURM_CONF": str(state / "slurm.conf")}
        done = subprocess.run([ZCHECK_EXE, "dataset", "submit", source, "--scene", BUNNY, "--quantity", "eye-z", "--diagnose",
                               "--tasks", "3", "--out", tmp_path / "run", "--wait"], capture_output=True, text=True,
                              timeout=600, env=env, cwd=m.root)
        assert done.returncode == 1, done.stdout + done.stderr  # inconsistent frames: the report's status
        assert "verify job" in done.stdout and "(3 tasks), report job" in done.stdout
        assert json.loads((tmp_path / "run" / "summary.json").read_text()) == json.loads((tmp_path / "single" / "summary.json").read_text())
        assert all((tmp_path / "run" / f"results-{i}.jsonl").exists() for i in range(3))
        assert "data:image/png;base64," in (tmp_path / "run" / "report.html").read_text()
    finally:
        subprocess.run(["bash", LOCAL_SLURM, "stop", state], capture_output=True, timeout=60)


def test_progress_is_shown_on_a_terminal_and_not_otherwise(made):
    import shlex
    import subprocess
    from helpers import ZCHECK_EXE
    m, p = made
    results = m.root / "progress.jsonl"
    command = shlex.join([ZCHECK_EXE, "dataset", "verify", str(p["transforms"]), "--scene", str(BUNNY), "--quantity",
                          "eye-z", "-o", str(results)])
    if results.exists():
        results.unlink()
    # `script` gives the command a terminal (util-linux); its output is what the terminal showed.
    shown = subprocess.run(["script", "-qec", command, "/dev/null"], capture_output=True, text=True, timeout=120)
    assert shown.returncode == 0, shown.stdout + shown.stderr
    assert f"frames {FRAMES}/{FRAMES}" in shown.stdout and "frames/s" in shown.stdout and "ETA" in shown.stdout
    results.unlink()
    code, records, out, err = verify(made, p["transforms"], results=results)
    assert "frames/s" not in err and err == ""


def test_a_gltf_scene_s_first_camera_is_its_own_and_takes_the_map_s_size(made):
    m, p = made
    code, out, err = run_cli("check", "--scene", p["gltf"], "--json")
    assert code == 0, err
    report = json.loads(out)
    assert any("the glTF's first, 'cam_000'" in w for w in report["warnings"])
    assert (report["camera"]["image"]["width"], report["camera"]["image"]["height"]) == (640, 480)
    # verify: the camera takes the map's size (320x240), near and far from the file
    np.save(m.root / "gltf_frame0.npy", m.eye_z(0))
    code, out, err = run_cli("verify", "--scene", p["gltf"], "--depth-map", m.root / "gltf_frame0.npy", "--quantity",
                             "eye-z", "--json")
    assert code == 0, out + err
    assert json.loads(out)["camera"]["image"] == {"width": 320, "height": 240}


def test_exported_npy_hdf5_and_colmap_maps_read_back_as_rendered(made, tmp_path):
    """zcheck export writes the formats datasets use; read_depth_map (and verify) read them back
    to the values rendered: the writers and readers are each other's inverse."""
    m, _ = made
    camera = m.trajectory.camera(2)
    camera_file = tmp_path / "camera.json"
    camera_file.write_text(camera.to_json())
    expected = m.checker.render(camera, "eye-z", route="raster")
    for name in ("d.npy", "d.h5", "d.geometric.bin"):
        code, _, err = run_cli("export", "--scene", BUNNY, "--camera", camera_file, "--backend", "raster",
                               "--quantity", "eye-z", "-o", tmp_path / name)
        assert code == 0, err
        back = zcheck.read_depth_map(tmp_path / name, camera, quantity="eye-z")
        hit = np.isfinite(expected)
        assert (np.isfinite(back) == hit).all(), name  # misses stay misses (COLMAP: 0)
        assert np.array_equal(back[hit], expected[hit].astype(np.float32).astype(np.float64)), name
        code, out, err = run_cli("verify", "--scene", BUNNY, "--camera", camera_file, "--depth-map", tmp_path / name,
                                 "--quantity", "eye-z")
        assert code == 0, out + err


def test_a_metashape_export_is_a_dataset_and_a_lost_chunk_scale_is_caught(made):
    m, _ = made
    good = m.metashape("cameras.xml")
    code, records, out, err = verify(made, good, "--depth", str(m.root / "depth" / "{stem}.npy"), rc=0)
    assert len(records) == FRAMES  # the disabled camera is skipped
    assert all(r["consistent"] and r["error"] is None for r in records), out + err
    # The chunk's scale left out: every frame's camera sits at the wrong place.
    lost = m.metashape("cameras_without_scale.xml", drop_scale=True)
    code, records, out, err = verify(made, lost, "--depth", str(m.root / "depth" / "{stem}.npy"), rc=1)
    assert len(records) == FRAMES and not any(r["consistent"] for r in records)
    # One camera of the file, converted: COLMAP's model of it reads back to the same projection.
    code, out, err = run_cli("camera", f"{good}#frame_005.JPG", "--near", "0.1", "--far", "50")
    assert code == 0, err
    shown = json.loads(out)
    assert shown["source"]["format"] == "metashape"
    assert shown["source"]["frame"] == "frame_005.JPG"

