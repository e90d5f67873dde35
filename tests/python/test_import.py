"""`import zcheck` does not load OpenImageIO (its ~260 shared libraries cost ~0.5 s); reading
an image file loads it on first use."""
import subprocess
import sys

CODE = """
import zcheck
def loaded():
    return any("libOpenImageIO" in line for line in open("/proc/self/maps"))
print(loaded())
scene = zcheck.Scene.from_file("builtin:default")
camera = scene.default_camera.replace(width=32, height=24)
print(zcheck.Checker(scene).check(camera).consistent, loaded())
try:
    zcheck.read_depth_map("/nonexistent.exr", camera, quantity="eye-z")
except zcheck.Error as e:
    print("error", loaded())
"""


def test_openimageio_is_loaded_only_when_an_image_file_is_read():
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[0] == "False"
    assert out[1] == "True False"
    assert out[2] == "error True"
