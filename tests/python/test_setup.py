"""The test command installs every module the tests import (scripts/deps.sh --test), so that on a
fresh Debian 12 machine no test is skipped, and none fails, for want of one.

Regression: the OpenCV oracle (test_lens_opencv.py) imported cv2 through pytest.importorskip, and
the set-up did not install python3-opencv, so on a fresh machine (CI) its 17 tests were skipped
without a word: zcheck's lens models went unchecked against OpenCV there."""
import ast
import re
import sys
from pathlib import Path

TESTS = Path(__file__).resolve().parent.parent
DEPS = TESTS.parent / "scripts" / "deps.sh"

# A module the tests import from outside the standard library and zcheck -> the Debian package
# that installs it for /usr/bin/python3. A new one goes here and into scripts/deps.sh.
DEBIAN_PACKAGE = {"numpy": "python3-numpy", "pytest": "python3-pytest", "h5py": "python3-h5py",
                  "cv2": "python3-opencv", "open3d": "python3-open3d", "vtk": "python3-vtk9"}
# Blender's own modules: the scripts under tests/blender run inside Blender.
INSIDE_BLENDER = {"bpy", "bpy_extras", "mathutils"}


def scripts_of_the_tests():
    return sorted(TESTS.rglob("*.py"))


def imports(path):
    """(module, line) of every absolute import in the file and of every pytest.importorskip call,
    and ("importorskip", line) of each such call."""
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield alias.name.split(".")[0], node.lineno
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            yield node.module.split(".")[0], node.lineno
        elif isinstance(node, ast.Call) and getattr(node.func, "attr", None) == "importorskip":
            yield "importorskip", node.lineno
            if node.args and isinstance(node.args[0], ast.Constant):
                yield str(node.args[0].value).split(".")[0], node.lineno


def packages_of_the_test_command():
    """The words of deps.sh's `packages=(...)` and `packages+=(...)` lists, comments left out."""
    text = DEPS.read_text()
    return {word for block in re.findall(r"packages\+?=\(([^)]*)\)", text)
            for word in re.sub(r"#[^\n]*", "", block).split()}


def test_regression_the_opencv_oracle_was_skipped_on_a_fresh_machine():
    installed = packages_of_the_test_command()
    local = {p.stem for p in scripts_of_the_tests()}
    assert {"python3", "python3-numpy", "colmap"} <= installed  # both lists were read
    problems = []
    for path in scripts_of_the_tests():
        where = path.relative_to(TESTS.parent)
        for module, line in imports(path):
            if module == "importorskip":
                problems.append(f"{where}:{line}: pytest.importorskip: an oracle the test command installs is "
                                f"imported, never skipped")
            elif module in sys.stdlib_module_names or module in local or module == "zcheck":
                continue
            elif module in INSIDE_BLENDER and path.parent.name == "blender":
                continue
            elif module not in DEBIAN_PACKAGE:
                problems.append(f"{where}:{line}: imports {module}, which no Debian package of this test knows: "
                                f"add it to DEBIAN_PACKAGE and to scripts/deps.sh")
            elif DEBIAN_PACKAGE[module] not in installed:
                problems.append(f"{where}:{line}: imports {module}, but scripts/deps.sh does not install "
                                f"{DEBIAN_PACKAGE[module]}")
    assert not problems, "\n".join(problems)
