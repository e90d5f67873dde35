"""Property tests over random cases (random_cases.py, fixed seeds): a correct map through every
lens model is consistent, a map with a material mistake never is, and the diagnosis names the
mistake made. Longer runs of the same generators found the regressions named in
tests/test_verify.cpp and tests/test_fit.cpp ("diagnose did not name ...")."""
import copy
import math

import numpy as np
import pytest

import zcheck
from random_cases import LENS_MODELS, SOUP_KINDS, changed_lens, lens_camera, materially_different, random_seed_of, soup

CASES_PER_MODEL = 8


@pytest.mark.parametrize("model", LENS_MODELS)
def test_every_lens_model_verifies_random_soups_and_rejects_a_wrong_lens(model):
    ran = rejected = 0
    refusals = []
    for k in range(4 * CASES_PER_MODEL):
        if ran == CASES_PER_MODEL:
            break
        rng = random_seed_of("lens", model, k)
        offset = [rng.choice([0.0, 0.0, 1e3, -3e4]) for _ in range(3)]
        vertices, triangles = soup(rng, SOUP_KINDS[k % len(SOUP_KINDS)], offset)
        camera_dict = lens_camera(rng, model, offset)
        quantity, dtype = rng.choice(["eye-z", "distance"]), rng.choice(["float32", "float64"])
        try:
            checker = zcheck.Checker(zcheck.Scene.from_arrays(vertices, triangles))
            camera = zcheck.Camera.from_dict(camera_dict)
            depth = checker.render(camera, quantity, route="ray", dtype=dtype)
            if not (np.isfinite(depth) & (depth > 0)).any():
                continue
            assert checker.check(camera).consistent, (k, camera_dict)
            report = checker.verify(camera, depth, quantity)
        except zcheck.Error as e:  # a lens that folds inside its image, eye-z beyond 90°: refused, and said why
            refusals.append(str(e))
            continue
        assert report.consistent, (k, quantity, dtype, camera_dict, report.summary())
        ran += 1
        how, wrong_dict = changed_lens(rng, camera_dict)
        try:
            wrong = checker.render(zcheck.Camera.from_dict(wrong_dict), quantity, route="ray", dtype="float64")
        except zcheck.Error:
            continue
        if materially_different(depth.astype(np.float64), wrong):
            assert not checker.verify(camera, wrong.astype(dtype), quantity).consistent, (k, how, camera_dict)
            rejected += 1
    assert all(r.startswith("camera dict: ") or "quantity eye-z" in r for r in refusals), refusals
    assert ran >= CASES_PER_MODEL // 2, (ran, refusals)
    assert rejected >= 1, (ran, rejected)


def pinhole_or_perspective(rng, scene):
    """A camera around `scene`, as dicts: perspective or pinhole, any convention and format."""
    d = scene.default_camera.to_dict()
    eye, target = np.array(d["view"]["eye"]), np.array(d["view"]["target"])
    distance = np.linalg.norm(eye - target)
    direction = np.array([rng.gauss(0, 1) for _ in range(3)])
    direction /= np.linalg.norm(direction)
    d["view"] = {"eye": list(target + direction * distance * rng.uniform(0.7, 1.5)), "target": list(target),
                 "up": [0, 1, 0] if abs(direction[1]) < 0.95 else [0, 0, 1]}
    w, h = rng.choice([96, 128, 160]), rng.choice([72, 96, 120])
    d["image"] = {"width": w, "height": h}
    d["convention"] = rng.choice(list(zcheck.conventions))
    near, far = distance * 10 ** rng.uniform(-3, -1), distance * rng.uniform(3, 50)
    if rng.random() < 0.5:
        d["projection"] = {"type": "perspective", "fovy_deg": rng.uniform(30, 75), "near": near, "far": far}
    else:
        f = rng.uniform(0.8, 1.6) * w
        d["projection"] = {"type": "pinhole", "fx": f, "fy": f, "cx": w / 2 - 0.5 + rng.uniform(-0.1, 0.1) * w,
                           "cy": h / 2 - 0.5 + rng.uniform(-0.1, 0.1) * h, "near": near, "far": far}
    d["depth"] = {"format": rng.choice(["float32", "unorm24", "unorm16"]), "reversed": rng.random() < 0.3}
    return d


def surfaces(camera, depth, quantity):
    return np.count_nonzero(np.isfinite(depth) & ((depth != camera.clear_value) if quantity in ("window", "ndc") else (depth > 0)))


# Each mistake: how the wrong map is made, from (rng, checker, camera dict) to (map, declared
# quantity), None where it does not apply; and the names that rightly explain it (a
# principal point off by half a pixel is also a sample offset, or intrinsics, fitted).
def _flipped(axis):
    def make(rng, checker, d):
        quantity = rng.choice(["window", "eye-z", "distance"])
        depth = checker.render(zcheck.Camera.from_dict(d), quantity, dtype="float32")
        return (depth[::-1] if axis == 0 else depth[:, ::-1]), quantity
    return make


def _rendered_as(change, quantities):
    def make(rng, checker, d):
        wrong = copy.deepcopy(d)
        if change(wrong) is False:
            return None
        quantity = rng.choice(quantities)
        return checker.render(zcheck.Camera.from_dict(wrong), quantity, dtype="float32"), quantity
    return make


def _swapped(made, declared):
    def make(rng, checker, d):
        if {made, declared} == {"window", "ndc"} and d["convention"] != "opengl":
            return None  # the same values in a [0, 1] convention
        return checker.render(zcheck.Camera.from_dict(d), made, dtype="float32"), declared
    return make


def _half_pixel(d):
    if d["projection"]["type"] != "pinhole":
        return False
    d["projection"]["cx"] -= 0.5
    d["projection"]["cy"] -= 0.5


def _half_fov(d):
    if d["projection"]["type"] != "perspective":
        return False
    d["projection"]["fovy_deg"] = 2 * math.degrees(math.atan(math.tan(math.radians(d["projection"]["fovy_deg"]))))


def _scaled(rng, checker, d):
    quantity = rng.choice(["eye-z", "distance"])
    depth = checker.render(zcheck.Camera.from_dict(d), quantity, dtype="float64")
    return (depth * rng.choice([1.05, 0.9, 1.2])).astype(np.float32), quantity


MISTAKES = {
    "y-flip": (_flipped(0), {"y-flip"}),
    "x-flip": (_flipped(1), {"x-flip"}),
    "half-pixel": (_rendered_as(_half_pixel, ["window", "eye-z"]), {"half-pixel", "sample-offset", "intrinsics"}),
    "reversed-as-standard": (_rendered_as(lambda d: d["depth"].update(reversed=not d["depth"]["reversed"]), ["window"]),
                             {"reversed-as-standard"}),
    "half-fov": (_rendered_as(_half_fov, ["window", "eye-z"]), {"half-fov"}),
    "near-far": (_rendered_as(lambda d: d["projection"].update(near=3 * d["projection"]["near"]), ["window"]), {"near-far"}),
    "depth-scale": (_scaled, {"depth-scale"}),
    "distance-as-eye-z": (_swapped("distance", "eye-z"), {"distance-as-eye-z"}),
    "eye-z-as-distance": (_swapped("eye-z", "distance"), {"eye-z-as-distance"}),
    "window-as-eye-z": (_swapped("window", "eye-z"), {"window-as-eye-z"}),
    "window-as-ndc": (_swapped("window", "ndc"), {"window-as-ndc", "ndc-range"}),  # the same values in OpenGL
}
SCENES = ("builtin:default", "builtin:terrain?n=64", "builtin:near-crossing")


@pytest.fixture(scope="module")
def checkers():
    return {name: zcheck.Checker(zcheck.Scene.from_file(name)) for name in SCENES}


@pytest.mark.parametrize("mistake", sorted(MISTAKES))
def test_a_map_with_a_mistake_is_inconsistent_and_the_diagnosis_names_it(mistake, checkers):
    make, names = MISTAKES[mistake]
    judged = 0
    for k in range(24):
        if judged == 6:
            break
        rng = random_seed_of("mistake", mistake, k)
        scene_name = rng.choice(SCENES)
        checker = checkers[scene_name]
        d = pinhole_or_perspective(rng, checker.scene)
        camera = zcheck.Camera.from_dict(d)
        made = make(rng, checker, d)
        if made is None:
            continue
        depth, quantity = made
        if surfaces(camera, depth, quantity) < 200:
            continue
        truth = checker.render(camera, quantity, dtype="float64")
        if quantity in ("eye-z", "distance") and not materially_different(truth, depth.astype(np.float64)):
            continue  # a flip of a symmetric view, a shift along a plane: no mistake to see
        try:
            report = checker.verify(camera, depth, quantity)
        except zcheck.Error as e:  # eye-z declared as window depth: refused, naming its values
            assert "holds no" in str(e), str(e)
            continue
        assert not report.consistent, (mistake, k, scene_name, d)
        first = next((h for h in checker.diagnose(camera, depth, quantity) if h["consistent"]), None)
        assert first is not None and first["hypothesis"] in names, (mistake, k, scene_name, d, first)
        judged += 1
    assert judged >= 3, (mistake, judged)
