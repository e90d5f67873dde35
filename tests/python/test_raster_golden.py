"""The raster route's output is a contract (fill rule, snapping, quantization): every pixel's
stored window depth and primitive id must stay bit-identical when the rasterizer is made
faster. The hashes in data/raster_golden_775678a.txt were recorded from the scalar rasterizer
of commit 775678a (before the speed work) for 192 configurations: built-in scenes (with
near-plane clipping) and five real meshes, under four conventions, three depth formats,
standard and reversed-Z, at 320x240. Every kernel form the processor runs must give them."""
import hashlib
import os
from pathlib import Path

import numpy as np
import pytest

import zcheck

GOLDEN = Path(__file__).parent / "data" / "raster_golden_775678a.txt"


def golden_rows():
    rows = {}
    for line in GOLDEN.read_text().splitlines():
        scene, convention, depth_format, reversed_z, digest = line.split()
        rows.setdefault(scene, []).append((convention, depth_format, reversed_z == "True", digest))
    return rows


@pytest.fixture(params=["baseline", "avx2", "avx512"])
def kernel_form(request, monkeypatch):
    """Each kernel form this processor runs (ZCHECK_KERNELS); the others are skipped, named."""
    if request.param not in zcheck.kernel_forms_supported():
        pytest.skip(f"this processor cannot run the {request.param} form")
    monkeypatch.setenv("ZCHECK_KERNELS", request.param)
    assert zcheck.kernel_form() == request.param
    return request.param


@pytest.mark.parametrize("scene_name", sorted(golden_rows()))
def test_raster_output_is_bit_identical_to_the_scalar_rasterizer(scene_name, kernel_form):
    models = os.environ.get("ZCHECK_MODELS_DIR", "")
    if scene_name.startswith("models/"):
        if not models:
            pytest.skip("ZCHECK_MODELS_DIR is not set")
        path = os.path.join(models, scene_name[len("models/"):])
    else:
        path = scene_name
    scene = zcheck.Scene.from_file(path)
    checker = zcheck.Checker(scene)
    for convention, depth_format, reversed_z, digest in golden_rows()[scene_name]:
        camera = scene.default_camera.replace(convention=convention, depth_format=depth_format,
                                              reversed=reversed_z, width=320, height=240)
        window = checker.render(camera, "window", route="raster", dtype=np.float64)
        primitive = checker.render(camera, "primitive-id", route="raster")
        got = hashlib.sha256(np.ascontiguousarray(window).tobytes() +
                             np.ascontiguousarray(primitive).tobytes()).hexdigest()[:16]
        assert got == digest, f"{scene_name} {convention} {depth_format} reversed={reversed_z} ({kernel_form} form)"
