"""The comparison's report is a contract: when the comparison is made faster, every count,
maximum, percentile, bias statistic and sample of `zcheck check --json`, the per-pixel
classes and ratios behind `--out`'s pictures, and the suite's results must stay the same,
bit for bit. The digests in data/compare_golden_4c34671.txt were recorded with the
comparison of commit 4c34671 (before its two-pass rewrite) for 84 checks (four scenes, two of
them real meshes, under three conventions, three depth formats, standard and reversed-Z, at
203x131, and the twelve example cameras), the pictures of four checks and the quick suite
(faults injected into either route). `python3 tests/python/test_compare_golden.py EXE`
prints the digests a build gives, in the file's format.

Four digests were recorded again when the comparison took a unorm format's |d_raster - d_ray|/q
as the difference times 2^N - 1, the quantum exactly (inQuanta; issue 46), where it had divided
by the quantum's double: the bunny in unorm16 with reversed-Z under the three conventions and
the quick suite. In each, one figure moved and nothing else: the mean signed error in quanta,
by 3 units in the last place (-0.009686778996405578 to -0.009686778996405583 under opengl, the
same step under direct3d and opencv) or 1 (-0.005827337893965418 to -0.0058273378939654175 in
the suite's twelfth configuration). The other 89 stayed as recorded. (The suite's digest, as
the others', holds only with ZCHECK_MODELS_DIR set: without it the suite runs without the
meshes.)

The reports hold Embree's hits too, and Embree picks its kernels by processor: the digests
were recorded where it runs its AVX-512 ones, and on a processor without them the test is
skipped rather than blame the comparison for a hit that moved across an edge."""
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

import zcheck
from helpers import REPO, ZCHECK_EXE

GOLDEN = Path(__file__).parent / "data" / "compare_golden_4c34671.txt"
FAULTS_ADDED_SINCE = ["lens-shift-dropped"]
SCENES = ["builtin:default", "builtin:near-crossing", "models/stanford-bunny.obj", "models/fandisk.obj"]
CAMERAS = ["dimetric", "frustum", "infinite-far", "isometric", "lens", "matrix-direct3d", "oblique-cabinet",
           "oblique-cavalier", "orthographic", "perspective", "pinhole", "trimetric"]
PICTURES = [["--scene", "builtin:default"],
            ["--scene", "models/stanford-bunny.obj", "--depth-format", "unorm16", "--convention", "direct3d"],
            ["--scene", "builtin:near-crossing", "--depth-format", "float32", "--reversed-z"],
            ["--scene", "builtin:default", "--camera", "examples/matrix-direct3d.json", "--width", "203",
             "--height", "131"]]


def digest(data):
    return hashlib.sha256(data).hexdigest()[:16]


def without(value, drop):
    """The document without the keys `drop` (timings) at any depth."""
    if isinstance(value, dict):
        return {k: without(v, drop) for k, v in value.items() if k not in drop}
    if isinstance(value, list):
        return [without(v, drop) for v in value]
    return value


def canonical(document, drop):
    return json.dumps(without(document, drop), sort_keys=True).encode()


def resolved(args, models):
    """Arguments with models/NAME and examples/NAME as paths."""
    out = []
    for a in args:
        if a.startswith("models/"):
            a = os.path.join(models, a[len("models/"):])
        elif a.startswith("examples/"):
            a = str(REPO / a)
        out.append(a)
    return out


def checks():
    """(label, arguments) of every check whose report is pinned."""
    for scene in SCENES:
        for convention in ["opengl", "direct3d", "opencv"]:
            for depth_format in ["unorm16", "unorm24", "float32"]:
                for reversed_z in [False, True]:
                    args = ["--scene", scene, "--convention", convention, "--depth-format", depth_format,
                            "--width", "203", "--height", "131"] + (["--reversed-z"] if reversed_z else [])
                    yield f"check:{scene}:{convention}:{depth_format}:{'reversed' if reversed_z else 'standard'}", args
    for camera in CAMERAS:
        yield f"check:camera:{camera}", ["--scene", "builtin:default", "--camera", f"examples/{camera}.json"]


def digests(exe, models):
    """label -> digest, for every pinned output of the zcheck executable `exe`. The reports name
    the meshes by path: the models folder is written `models/` in them, wherever it is."""
    models = os.path.realpath(models)

    def digest_of(document, drop):
        # Keys added since the digests were recorded, which a check's report holds empty (what a
        # verified map declares, its holes and its values out of range: issue 36), are left out:
        # the rest must not change.
        # So are the faults added to the catalogue since (lens-shift-dropped: issue 43), from the
        # suite's detection table and each configuration's faults.
        # And the suite's lens part (issue 45), its own block beside the linear matrix's.
        drop = [*drop, "declared", "holes", "out_of_range", "lens", *FAULTS_ADDED_SINCE]
        text = canonical(document, drop).decode().replace(json.dumps(models)[1:-1] + "/", "models/")
        return digest(text.encode())

    def run(*args):
        done = subprocess.run([exe, *args], capture_output=True, timeout=300)
        assert done.returncode in (0, 1), f"{args}: rc {done.returncode}\n{done.stderr.decode()}"
        return done.stdout
    out = {}
    for label, args in checks():
        report = json.loads(run("check", *resolved(args, models), "--json"))
        out[label] = digest_of(report, ["timings_ms", "zcheck_version", "version"])
    for k, args in enumerate(PICTURES):
        with tempfile.TemporaryDirectory() as folder:
            run("check", *resolved(args, models), "--out", folder)
            pictures = b"".join((Path(folder) / name).read_bytes()
                                for name in ["coverage_classes.png", "error_heatmap.png"])
            report = json.loads((Path(folder) / "report.json").read_text())
        out[f"pictures:{k}"] = digest(pictures)
        out[f"pictures-report:{k}"] = digest_of(report, ["timings_ms", "zcheck_version", "version"])
    with tempfile.TemporaryDirectory() as folder:
        results = Path(folder) / "suite.json"
        run("suite", "--quick", "--out", folder)
        out["suite:quick"] = digest_of(json.loads(results.read_text()), ["seconds", "milliseconds", "zcheck_version", "version"])
    return out


def has_avx512():
    flags = set(Path("/proc/cpuinfo").read_text().split()) if Path("/proc/cpuinfo").exists() else set()
    return {"avx512f", "avx512cd", "avx512dq", "avx512bw", "avx512vl"} <= flags


@pytest.mark.parametrize("form", ["baseline", "avx2", "avx512"])
def test_the_comparison_reports_what_it_reported_before_it_was_made_faster(form, monkeypatch):
    """In each kernel form zcheck has (ZCHECK_KERNELS), where this processor runs it."""
    models = os.environ.get("ZCHECK_MODELS_DIR", "")
    if not models:
        pytest.skip("ZCHECK_MODELS_DIR is not set")
    if not has_avx512():
        pytest.skip("recorded where Embree runs its AVX-512 kernels; this processor has none")
    if form not in zcheck.kernel_forms_supported():
        pytest.skip(f"this processor cannot run the {form} form")
    monkeypatch.setenv("ZCHECK_KERNELS", form)
    expected = dict(line.split() for line in GOLDEN.read_text().splitlines())
    got = digests(ZCHECK_EXE, models)
    assert sorted(got) == sorted(expected)
    differing = [label for label in expected if got[label] != expected[label]]
    assert not differing, f"{len(differing)} of {len(expected)} differ in the {form} form, such as {differing[:5]}"


if __name__ == "__main__":
    for label, value in digests(sys.argv[1], os.environ["ZCHECK_MODELS_DIR"]).items():
        print(label, value)
