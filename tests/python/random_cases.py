"""Random scenes, cameras and mistakes for the property tests (test_properties.py): what a
renderer or a dataset may throw at zcheck, drawn from a seeded generator so that every run is the
same. The C++ property tests draw theirs from tests/random_scenes.h; these add every lens model,
wrong maps and the diagnosis."""
import copy
import math
import random

import numpy as np

SOUP_KINDS = ("intersect", "coplanar", "edgeon", "nearfar", "fan", "tiny")

LENS_MODELS = ("opencv", "brown_conrady", "opencv_fisheye", "thin_prism_fisheye", "fisheye624", "fov", "division",
               "unified", "eucm", "double_sphere", "metashape_frame", "metashape_fisheye", "equisolid",
               "equirectangular", "blender_fisheye_equidistant", "blender_fisheye_equisolid",
               "blender_fisheye_lens_polynomial", "blender_mirror_ball", "blender_equiangular_cubemap_face")


def soup(rng, kind, offset=(0.0, 0.0, 0.0)):
    """A triangle soup in front of an eye at `offset` looking down -z: (vertices, triangles)."""
    vertices, triangles = [], []

    def triangle(a, b, c):
        n = len(vertices)
        vertices.extend([a, b, c])
        triangles.append((n, n + 1, n + 2))

    def uniform3(lo, hi):
        return np.array([rng.uniform(lo[k], hi[k]) for k in range(3)])

    for _ in range(rng.randint(1, 300)):
        if kind == "intersect":  # big triangles through each other
            c, s = uniform3((-1, -1, -6), (1, 1, -2)), rng.uniform(0.5, 3)
            triangle(*(c + uniform3((-s,) * 3, (s,) * 3) for _ in range(3)))
        elif kind == "coplanar":  # overlapping triangles in a few shared planes
            z = rng.choice([-2.0, -3.0, -3.0000001, -4.5])
            triangle(*(np.array([rng.uniform(-2, 2), rng.uniform(-2, 2), z]) for _ in range(3)))
        elif kind == "edgeon":  # triangles almost holding the eye
            c = uniform3((-1, -1, -6), (1, 1, -1))
            d = c / np.linalg.norm(c)
            e = np.cross(d, [0, 1, 0])
            e /= np.linalg.norm(e)
            t = rng.uniform(0.05, 1)
            triangle(c, c + d * t + e * rng.uniform(-1e-4, 1e-4), c + e * t * rng.uniform(0.5, 2))
        elif kind == "nearfar":  # crossing the near and far planes
            triangle(*(uniform3((-3, -3, -30), (3, 3, 0.5)) for _ in range(3)))
        elif kind == "fan":  # a fan of shared vertices
            c, r, m, a0 = uniform3((-1, -1, -5), (1, 1, -2)), rng.uniform(0.1, 2), rng.randint(3, 40), rng.uniform(0, 6.3)
            ring = [c + np.array([r * math.cos(a0 + 2 * math.pi * i / m), r * math.sin(a0 + 2 * math.pi * i / m),
                                  rng.uniform(-0.5, 0.5)]) for i in range(m)]
            for i in range(m):
                triangle(c, ring[i], ring[(i + 1) % m])
        else:  # tiny
            c, s = uniform3((-1, -1, -5), (1, 1, -1)), 10 ** rng.uniform(-5, -2)
            triangle(*(c + uniform3((-s,) * 3, (s,) * 3) for _ in range(3)))
    return np.array(vertices) + np.asarray(offset, dtype=np.float64), np.array(triangles)


def lens_camera(rng, model, offset=(0.0, 0.0, 0.0)):
    """A camera dict of lens `model` at `offset` looking about -z, parameters in the ranges real
    calibrations give (tests/test_lens.cpp's), near and far anywhere sensible."""
    u = rng.uniform
    w, h = rng.randint(2, 160), rng.randint(2, 120)
    f = u(0.3, 1.5) * max(w, h)
    k = {"fx": f, "fy": f * u(0.9, 1.1), "cx": w / 2 - 0.5 + u(-0.1, 0.1) * w, "cy": h / 2 - 0.5 + u(-0.1, 0.1) * h}
    lens = {"model": model}
    if model == "opencv":
        lens.update(k1=u(-0.3, 0.3), k2=u(-0.1, 0.1), p1=u(-0.01, 0.01), p2=u(-0.01, 0.01), k3=u(-0.02, 0.02),
                    k4=u(-0.1, 0.1), s1=u(-1e-3, 1e-3), tau_x=u(-0.01, 0.01))
    elif model == "brown_conrady":
        lens.update(k1=u(-0.3, 0.3), k2=u(-0.05, 0.05), k3=u(-0.01, 0.01), k4=u(-1e-3, 1e-3), p1=u(-0.01, 0.01),
                    p2=u(-0.01, 0.01))
    elif model == "opencv_fisheye":
        lens.update(k1=u(-0.05, 0.05), k2=u(-0.01, 0.01), k3=u(-1e-3, 1e-3), k4=u(-1e-4, 1e-4))
    elif model == "thin_prism_fisheye":
        lens.update(k1=u(-0.05, 0.05), k2=u(-0.01, 0.01), p1=u(-1e-3, 1e-3), p2=u(-1e-3, 1e-3), sx1=u(-1e-3, 1e-3),
                    sy1=u(-1e-3, 1e-3))
    elif model == "fisheye624":
        lens.update(k0=u(-0.05, 0.05), k1=u(-0.02, 0.02), p0=u(-1e-3, 1e-3), s0=u(-1e-3, 1e-3), s3=u(-1e-4, 1e-4))
    elif model == "fov":
        lens.update(omega=u(0.2, 1.6))
    elif model == "division":
        lens.update(k=u(-0.4, 0.1))
    elif model == "unified":
        lens.update(xi=u(0, 1.6), k1=u(-0.1, 0.1), k2=u(-0.02, 0.02), p1=u(-1e-3, 1e-3))
    elif model == "eucm":
        lens.update(alpha=u(0.3, 0.8), beta=u(0.6, 1.5))
    elif model == "double_sphere":
        lens.update(xi=u(-0.3, 0.3), alpha=u(0.4, 0.7))
    elif model in ("metashape_frame", "metashape_fisheye"):
        lens.update(f=f, cx=u(-0.1, 0.1) * w, cy=u(-0.1, 0.1) * h, b1=u(-5, 5), b2=u(-1, 1), k1=u(-0.05, 0.05),
                    k2=u(-0.02, 0.02), p1=u(-1e-3, 1e-3), p2=u(-1e-3, 1e-3))
        k = None
    elif model == "equirectangular":
        lon, lat = u(30, 360), u(20, 180)
        lon_min, lat_min = u(-180, 180 - lon), u(-90, 90 - lat)
        lens.update(lon_min_deg=lon_min, lon_max_deg=lon_min + lon, lat_min_deg=lat_min, lat_max_deg=lat_min + lat)
        k = None
    elif model.startswith("blender_"):
        k = None
        lens.update(shift_x=u(-0.2, 0.2), shift_y=u(-0.2, 0.2))
        sensor = u(20, 40)
        if model == "blender_fisheye_equidistant":
            lens.update(fisheye_fov=u(0.5, 2 * math.pi))
        elif model == "blender_fisheye_equisolid":
            lens.update(fisheye_lens=u(6, 16), fisheye_fov=u(1, 2 * math.pi), fitted_sensor_width=sensor,
                        fitted_sensor_height=sensor * h / w * u(0.9, 1.1))
        elif model == "blender_fisheye_lens_polynomial":
            lens.update(fisheye_polynomial_k0=0.0, fisheye_polynomial_k1=u(-0.09, -0.04),
                        fisheye_polynomial_k2=u(-5e-4, 5e-4), fisheye_polynomial_k3=u(-1e-5, 1e-5),
                        fisheye_polynomial_k4=u(-1e-7, 1e-7), fisheye_fov=u(1.5, math.pi), fitted_sensor_width=sensor,
                        fitted_sensor_height=sensor * h / w * u(0.9, 1.1))
        elif model == "blender_equiangular_cubemap_face":
            lens.update(shift_x=u(-0.5, 0.5), shift_y=u(-0.5, 0.5))
    near = 10 ** u(-3, -0.5)
    projection = {"near": near, "far": near * 10 ** u(1, 5)}
    if k:
        projection = dict(type="pinhole", **k, **projection)
    return {"convention": rng.choice(["opencv", "opengl", "direct3d", "vulkan", "metal"]), "image": {"width": w, "height": h},
            "projection": projection, "lens": lens,
            "view": {"eye": list(offset), "target": [offset[0] + u(-0.3, 0.3), offset[1] + u(-0.3, 0.3), offset[2] - 1],
                     "up": [0, 1, 0]}}


def changed_lens(rng, camera):
    """The camera with one thing about its lens wrong, as a calibration slip makes it: the
    distortion dropped, the principal point half a pixel off, the focal length 2 % off, or one
    parameter changed by a tenth. (name, camera dict)."""
    c = copy.deepcopy(camera)
    lens, projection = c["lens"], c["projection"]
    keys = [key for key in lens if key != "model"]
    ways = ["no-lens", "focal"] if "fx" in projection else ["focal"] if "f" in lens else []
    ways += ["principal-point"] if "cx" in projection or "cx" in lens or "shift_x" in lens else []
    ways += ["parameter"] if keys else []
    how = rng.choice(ways)
    if how == "no-lens":
        del c["lens"]
    elif how == "principal-point":
        if "cx" in projection:
            projection["cx"] += 0.5
            projection["cy"] += 0.5
        elif "cx" in lens:
            lens["cx"] += 0.5
            lens["cy"] += 0.5
        else:
            lens["shift_x"] += 0.5 / c["image"]["width"]
            lens["shift_y"] += 0.5 / c["image"]["height"]
    elif how == "focal":
        if "fx" in projection:
            projection["fx"] *= 1.02
            projection["fy"] *= 1.02
        else:
            lens["f"] *= 1.02
    else:
        key = rng.choice(keys)
        lens[key] = lens[key] * 1.1 + 0.02
        how = "parameter " + key
    return how, c


def materially_different(truth, other):
    """Whether two maps of eye-z or distance differ beyond any tolerance at 20 pixels or more
    and at 5 % of those either sees a surface at: coverage, or over 1 % of the depth."""
    seen_a = np.isfinite(truth) & (truth > 0)
    seen_b = np.isfinite(other) & (other > 0)
    both = seen_a & seen_b
    far_off = np.abs(truth[both] - other[both]) > 1e-2 * np.abs(truth[both]) + 2e-3
    count = np.count_nonzero(seen_a != seen_b) + np.count_nonzero(far_off)
    return count >= max(20, 0.05 * np.count_nonzero(seen_a | seen_b))


def random_seed_of(*parts):
    """A generator seeded by `parts`, the same on every run."""
    return random.Random(":".join(map(str, parts)))
