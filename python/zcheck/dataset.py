"""Datasets of depth maps: every frame of a transforms.json (nerfstudio, instant-ngp), a COLMAP
model or a zcheck manifest (JSON Lines), as `zcheck dataset verify` reads them.

    import zcheck.dataset
    frames = zcheck.dataset.open("transforms.json", scene="mesh.ply", quantity="eye-z")
    len(frames), frames[3].name, frames[3].depth           # a sequence of Frame
    camera, depth = frames[3].load()                        # the frame's camera and its map
    for record in zcheck.dataset.verify("transforms.json", scene="mesh.ply", quantity="eye-z"):
        print(record["frame"], record["consistent"])        # the records `dataset verify` writes

A frame's own values (a manifest line's) win over the arguments, which win over what its camera
file implies (nerfstudio's millimetre PNGs: scale 1000). Cameras without near and far take them
from the scene as the camera sees it and from the map's depths; cameras without an image size
(instant-ngp, glTF) take the map's. Bad sources and arguments raise zcheck.Error; a frame that
cannot be verified is a record with its error, and the run goes on.

Everything here pickles (Camera, Scene, Report, Frame), so frames may be spread over
multiprocessing or concurrent.futures workers:

    def check(frame):                                   # in a worker
        camera, _ = frame.load()
        return frame.checker().verify_file(camera, frame.depth, frame.quantity, **frame.reading)
"""
import json as _json

from . import Checker, Scene

__all__ = ["Dataset", "Frame", "open", "verify"]


def _files():
    from . import _zcheck_files
    return _zcheck_files


_OPTIONS = ("quantity", "depth", "camera_format", "scale", "offset", "miss", "channel", "near", "far", "convention",
            "quantum", "rel_tolerance", "abs_tolerance", "noise_model", "allow_holes")
_DECLARED = ("quantum", "rel_tolerance", "abs_tolerance", "noise_model", "allow_holes")


class Frame:
    """One frame: its name, index, depth map path, how the map is read, and its camera.

    index, name  the frame's place in the source and its name (an image name, a file path, the
                 manifest's "frame")
    depth        the depth map's path
    quantity     "window", "ndc", "eye-z" or "distance"
    reading      the keyword arguments Checker.verify_file and read_depth_map take for it
                 (channel, scale, offset, miss, and what the map declares: quantum, rel_tolerance,
                 abs_tolerance, noise_model, allow_holes), as the frame reads its map
    scene        the scene's name or path
    error        why the frame cannot be verified ("" when it can): a camera the file refused,
                 a malformed manifest line
    notes        what was assumed (a scale the camera file implies)
    """

    def __init__(self, dataset, index):
        self._dataset = dataset
        info = dataset._native.frame(index)
        self.index = info["index"]
        self.name = info["name"]
        self.depth = info["depth"]
        self.quantity = info["quantity"]
        self.reading = dict(info["reading"])
        self.scene = info["scene"]
        self.error = info["error"]
        self.notes = list(info["notes"]) if "notes" in info else []

    def load(self):
        """(camera, depth): the frame's zcheck.Camera, completed for its scene and map, and its map as
        an (H, W) float64 array (NaN where it holds no depth). Raises zcheck.Error as the frame's
        record would say."""
        if self.error:
            from . import Error
            raise Error(self.error)
        return self._dataset._native.camera_and_map(self.index)

    def checker(self):
        """A Checker of the frame's scene (built once per process and scene)."""
        return _checker(self.scene)

    def __reduce__(self):
        return (_frame_of, (self._dataset, self.index))

    def __repr__(self):
        return f"<zcheck.dataset.Frame {self.index} '{self.name}': {self.depth}{' (error)' if self.error else ''}>"


_checkers = {}


def _checker(scene):
    if scene not in _checkers:
        _checkers[scene] = Checker(Scene.from_file(scene))
    return _checkers[scene]


def _frame_of(dataset, index):
    return dataset[index]


class Dataset:
    """The frames of a source (a sequence: len, indexing, iteration). See open()."""

    def __init__(self, source, scene="builtin:default", **options):
        unknown = set(options) - set(_OPTIONS) - {"diagnose", "shard"}
        if unknown:
            from . import Error
            raise Error(f"zcheck.dataset.open: unknown argument {sorted(unknown)[0]!r}")
        self._args = (str(source), str(scene), options)
        values = {name: options.get(name) for name in _OPTIONS}
        self._native = _files()._Dataset(str(source), str(scene), values["quantity"], values["depth"],
                                         values["camera_format"], values["scale"], values["offset"], values["miss"],
                                         values["channel"], values["near"], values["far"], values["convention"],
                                         bool(options.get("diagnose", False)), options.get("shard"),
                                         {name: values[name] for name in _DECLARED})
        self.source = self._native.source
        self.kind = self._native.kind

    def __len__(self):
        return len(self._native)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        if index < 0:
            index += len(self)
        if not 0 <= index < len(self):
            raise IndexError(f"frame {index} of a dataset of {len(self)}")
        return Frame(self, index)

    def __iter__(self):
        for i in range(len(self)):
            yield Frame(self, i)

    def __reduce__(self):
        source, scene, options = self._args
        return (_dataset_of, (source, scene, options))

    def __repr__(self):
        return f"<zcheck.dataset.Dataset {self.kind} '{self.source}': {len(self)} frames>"


_datasets = {}


def _dataset_of(source, scene, options):
    """A pickled dataset (or frame) opened again, once per process."""
    key = (source, scene, _json.dumps(options, sort_keys=True, default=str))
    if key not in _datasets:
        _datasets[key] = Dataset(source, scene, **options)
    return _datasets[key]


def open(source, scene="builtin:default", **options):  # noqa: A001 - the module's verb, as zcheck.dataset.open
    """The frames of `source`: a transforms.json, a COLMAP model folder, or a manifest (.jsonl).

scene:         the mesh (or builtin:...) the frames are checked against, unless a manifest line
               names its own
quantity:      what the maps hold, unless a line says: "window", "ndc", "eye-z", "distance"
depth:         COLMAP: each image's depth map, "{name}" the image name, "{stem}" without extension
camera_format: the source's format when its content should not decide
scale, offset, miss, channel: how maps are read (as `zcheck verify`'s options)
quantum, rel_tolerance, abs_tolerance, allow_holes: what the maps declare (as Checker.verify's),
               unless a manifest line says
near, far:     the clip planes of cameras whose file has none
convention:    replaces every camera's convention
"""
    return Dataset(source, scene, **options)


def verify(source, scene="builtin:default", *, diagnose=False, shard=None, threads=None, chunk=None, **options):
    """Verifies every frame (of `shard`, "I/N") as `zcheck dataset verify` does, yielding the records it
writes (dicts), a few frames at a time as they finish; frames run in parallel inside each chunk
(`chunk` frames, default four per thread). Arguments as open()'s."""
    dataset = Dataset(source, scene, diagnose=diagnose, shard=shard, **options)
    frames = dataset._native.shard_frames()
    step = chunk or 4 * (threads or _cpu_count())
    for start in range(0, len(frames), step):
        for line in dataset._native.verify(frames[start:start + step], threads):
            yield _json.loads(line)


def _cpu_count():
    import os
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
