#!/usr/bin/env python3
"""Writes frames.xml, frames_v2.xml and expected.json in this folder (run with /usr/bin/python3).

The scene is designed in WORLD coordinates (cameras about 5 units from the world origin, each
looking at it), then expressed the way Metashape stores it:

    world = s * R @ p + t          (chunk <transform>: rotation R, translation t, scale s;
                                    p = chunk-internal coordinates)
    <camera><transform>            = 4x4 camera-to-internal matrix, row-major, rigid,
                                     camera axes x right, y down, z forward (OpenCV)

frames.xml    1.x style: the similarity is the chunk-level <transform> (after <cameras>).
frames_v2.xml 2.x style: the same similarity is <components>/<component id="0">/<transform>,
              aligned cameras carry component_id="0"; there is no chunk-level <transform>.
Both files must give the same expected.json.

expected.json is then computed from the XML text as a reader would (ElementTree parse, the
numbers as written), and checked against the designed world poses. Projections use the camera
models of Metashape's manual (appendix "Camera models"), written out in numpy below:
frame_project (frame sensors: Brown polynomial with P1 on r^2 + 2x^2, u = w/2 + cx + x'(f + b1)
+ y' b2, v = h/2 + cy + y' f), fisheye_project (the same on the equidistant point), and
spherical_project (a spherical sensor without calibration: the whole sphere, longitude
atan2(X, Z) = 0 at the centre column, the top row up; the convention nerfstudio's
metashape_utils.py reads, see NOTES.md).
"""
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent

# ---------------------------------------------------------------- design ----
W, H = 640, 480
# sensor 0, calibration class="adjusted" (the one to use)
F, CX, CY, B1, B2 = 600.5, 3.5, -2.25, 0.0, 0.0
# sensor 0, calibration class="initial" (written first; must NOT be used)
F_INITIAL, CX_INITIAL, CY_INITIAL = 585.0, 0.0, 0.0
# sensor 1: a distorted frame camera (nonzero k1..k4, p1, p2, b1, b2): lens metashape_frame
F1, CX1, CY1, B1_1, B2_1 = 610.25, 1.5, -0.75, 0.8, -0.35
K1_1, K2_1, K3_1, K4_1, P1_1, P2_1 = -0.0523, 0.0117, -0.0009, 0.00013, 0.00041, -0.00023
# sensor 3: a fisheye (equidistant) camera: lens metashape_fisheye
F3, CX3, CY3, B1_3, B2_3 = 201.5, -2.25, 1.75, 0.6, -0.2
K1_3, K2_3, K3_3, K4_3, P1_3, P2_3 = 0.021, -0.004, 0.0007, -0.0001, 0.0002, -0.0001
# sensor 4: a spherical camera (no calibration), 2:1: lens equirectangular over the sphere
W4, H4 = 1024, 512
# sensor 5: a cylindrical camera -> its cameras must be refused

# chunk similarity: world = s * R @ p + t
AXIS = np.array([1.0, 2.0, 2.0]) / 3.0   # unit axis
ANGLE_DEG = 30.0
T_CHUNK = np.array([10.0, -4.0, 2.5])
S_CHUNK = 2.0

UP = np.array([0.0, 0.0, 1.0])           # world up used to build look-at poses
DIST = 5.0


def rodrigues(axis, deg):
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    th = math.radians(deg)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(th) * k + (1 - math.cos(th)) * (k @ k)


def look_at_opencv(center, target, up, roll_deg=0.0):
    """World-from-camera rotation, camera axes x right, y down, z forward."""
    fwd = target - center
    fwd = fwd / np.linalg.norm(fwd)
    right = np.cross(fwd, up)
    right = right / np.linalg.norm(right)
    down = np.cross(fwd, right)
    r = np.stack([right, down, fwd], axis=1)
    if roll_deg:
        r = r @ rodrigues([0, 0, 1], roll_deg)  # roll about the camera's own z axis
    return r


def center_from(az_deg, el_deg):
    az, el = math.radians(az_deg), math.radians(el_deg)
    return DIST * np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])


# id, label, sensor_id, in_group, enabled attribute (None = absent), aligned, az, el, roll
CAMERAS = [
    dict(id=0, label="IMG_0001.JPG", sensor=0, group=False, enabled=None, aligned=True, az=0.0, el=20.0, roll=0.0),
    dict(id=1, label="IMG_0002.JPG", sensor=0, group=True, enabled=None, aligned=True, az=70.0, el=10.0, roll=7.0),
    dict(id=2, label="IMG_0003.JPG", sensor=0, group=False, enabled="true", aligned=True, az=150.0, el=30.0, roll=0.0),
    dict(id=3, label="IMG_0004.JPG", sensor=0, group=True, enabled="false", aligned=True, az=220.0, el=15.0, roll=0.0),
    dict(id=4, label="IMG_0005.JPG", sensor=0, group=False, enabled=None, aligned=False, az=260.0, el=20.0, roll=0.0),
    dict(id=5, label="IMG_0101.JPG", sensor=1, group=False, enabled=None, aligned=True, az=300.0, el=25.0, roll=0.0),
    dict(id=6, label="IMG_0201.JPG", sensor=3, group=False, enabled=None, aligned=True, az=30.0, el=40.0, roll=12.0),
    dict(id=7, label="IMG_0301.JPG", sensor=4, group=False, enabled=None, aligned=True, az=110.0, el=5.0, roll=-20.0),
    dict(id=8, label="IMG_0401.JPG", sensor=5, group=False, enabled=None, aligned=True, az=190.0, el=15.0, roll=0.0),
]

PROBE_POINTS = [[0.0, 0.0, 0.0], [0.3, -0.2, 0.4], [-0.5, 0.25, -0.1]]

# More probes for the lens cameras, as directions in the camera frame (angle from the axis in
# degrees, azimuth in degrees) at distance 3: to the image's edges for the frame camera, to 80
# degrees for the fisheye (Metashape's fisheye formula divides by Z), all round for the sphere.
LENS_PROBES = {
    1: [(10, 30), (20, 135), (26, -60), (30, 200), (32, 37)],
    3: [(15, 20), (40, 100), (60, -150), (75, 260), (80, 45)],
    4: [(50, 10), (90, 60), (120, 200), (160, -45), (179, 30), (30, 250)],
}

R_CHUNK = rodrigues(AXIS, ANGLE_DEG)


def designed_world_from_camera(cam):
    c = center_from(cam["az"], cam["el"])
    r = look_at_opencv(c, np.zeros(3), UP, cam["roll"])
    m = np.eye(4)
    m[:3, :3] = r
    m[:3, 3] = c
    return m


def lens_probe_points(cam):
    """World points of the camera's LENS_PROBES (sensor's), from the designed pose."""
    wc = designed_world_from_camera(cam)
    out = []
    for theta_deg, phi_deg in LENS_PROBES.get(cam["sensor"], []):
        th, ph = math.radians(theta_deg), math.radians(phi_deg)
        d = np.array([math.sin(th) * math.cos(ph), math.sin(th) * math.sin(ph), math.cos(th)])
        out.append((wc[:3, :3] @ (3.0 * d) + wc[:3, 3]).tolist())
    return out


def internal_camera_transform(world_from_camera):
    """What Metashape writes in <camera><transform>: camera -> chunk-internal, rigid."""
    r_int = R_CHUNK.T @ world_from_camera[:3, :3]
    c_int = R_CHUNK.T @ (world_from_camera[:3, 3] - T_CHUNK) / S_CHUNK
    m = np.eye(4)
    m[:3, :3] = r_int
    m[:3, 3] = c_int
    return m


# ---------------------------------------------------------------- writer ----
def num(x):
    x = float(x) + 0.0  # no "-0"
    return format(x, ".17g")


def nums(a):
    return " ".join(num(v) for v in np.asarray(a, float).ravel())


def spd(seed, scale):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(3, 3))
    return scale * (a @ a.T + 3 * np.eye(3))


def sensors_xml(v2):
    extra = '        <black_level>0 0 0</black_level>\n        <sensitivity>1 1 1</sensitivity>\n' if v2 else ""
    cov0 = np.diag([0.61, 0.094, 0.088]) + 0.001
    return f"""    <sensors next_id="6">
      <sensor id="0" label="Synthetic 4.8mm (4.8mm)" type="frame">
        <resolution width="{W}" height="{H}"/>
        <property name="pixel_width" value="0.0080000000000000002"/>
        <property name="pixel_height" value="0.0080000000000000002"/>
        <property name="focal_length" value="4.7999999999999998"/>
        <property name="layer_index" value="0"/>
        <bands>
          <band label="Red"/>
          <band label="Green"/>
          <band label="Blue"/>
        </bands>
        <data_type>uint8</data_type>
        <calibration type="frame" class="initial">
          <resolution width="{W}" height="{H}"/>
          <f>{num(F_INITIAL)}</f>
          <cx>{num(CX_INITIAL)}</cx>
          <cy>{num(CY_INITIAL)}</cy>
        </calibration>
        <calibration type="frame" class="adjusted">
          <resolution width="{W}" height="{H}"/>
          <f>{num(F)}</f>
          <cx>{num(CX)}</cx>
          <cy>{num(CY)}</cy>
          <b1>{num(B1)}</b1>
          <b2>{num(B2)}</b2>
          <k1>0</k1>
          <k2>0</k2>
          <k3>0</k3>
          <p1>0</p1>
          <p2>0</p2>
        </calibration>
{extra}        <covariance>
          <params>f cx cy</params>
          <coeffs>{nums(cov0)}</coeffs>
        </covariance>
        <meta>
          <property name="Exif/Make" value="Synthetic"/>
          <property name="Exif/Model" value="S-4.8"/>
          <property name="Exif/FocalLength" value="4.8"/>
        </meta>
      </sensor>
      <sensor id="1" label="Distorted 4.9mm (4.9mm)" type="frame">
        <resolution width="{W}" height="{H}"/>
        <property name="pixel_width" value="0.0080000000000000002"/>
        <property name="pixel_height" value="0.0080000000000000002"/>
        <property name="focal_length" value="4.9000000000000004"/>
        <property name="layer_index" value="0"/>
        <bands>
          <band label="Red"/>
          <band label="Green"/>
          <band label="Blue"/>
        </bands>
        <data_type>uint8</data_type>
        <calibration type="frame" class="adjusted">
          <resolution width="{W}" height="{H}"/>
          <f>{num(F1)}</f>
          <cx>{num(CX1)}</cx>
          <cy>{num(CY1)}</cy>
          <b1>{num(B1_1)}</b1>
          <b2>{num(B2_1)}</b2>
          <k1>{num(K1_1)}</k1>
          <k2>{num(K2_1)}</k2>
          <k3>{num(K3_1)}</k3>
          <k4>{num(K4_1)}</k4>
          <p1>{num(P1_1)}</p1>
          <p2>{num(P2_1)}</p2>
        </calibration>
{extra}        <covariance>
          <params>f cx cy k1 k2 k3 p1 p2</params>
          <coeffs>{nums(np.diag([0.7, 0.1, 0.1, 1e-6, 2e-6, 3e-6, 1e-8, 1e-8]))}</coeffs>
        </covariance>
      </sensor>
      <sensor id="3" label="Fisheye 1.8mm (1.8mm)" type="fisheye">
        <resolution width="{W}" height="{H}"/>
        <property name="pixel_width" value="0.0080000000000000002"/>
        <property name="pixel_height" value="0.0080000000000000002"/>
        <property name="focal_length" value="1.8"/>
        <property name="layer_index" value="0"/>
        <bands>
          <band label="Red"/>
          <band label="Green"/>
          <band label="Blue"/>
        </bands>
        <data_type>uint8</data_type>
        <calibration type="fisheye" class="adjusted">
          <resolution width="{W}" height="{H}"/>
          <f>{num(F3)}</f>
          <cx>{num(CX3)}</cx>
          <cy>{num(CY3)}</cy>
          <b1>{num(B1_3)}</b1>
          <b2>{num(B2_3)}</b2>
          <k1>{num(K1_3)}</k1>
          <k2>{num(K2_3)}</k2>
          <k3>{num(K3_3)}</k3>
          <k4>{num(K4_3)}</k4>
          <p1>{num(P1_3)}</p1>
          <p2>{num(P2_3)}</p2>
        </calibration>
{extra}        <covariance>
          <params>f cx cy k1 k2 k3 k4 p1 p2</params>
          <coeffs>{nums(np.diag([0.5, 0.1, 0.1, 1e-6, 2e-6, 3e-6, 4e-6, 1e-8, 1e-8]))}</coeffs>
        </covariance>
      </sensor>
      <sensor id="4" label="unknown" type="spherical">
        <resolution width="{W4}" height="{H4}"/>
        <property name="layer_index" value="0"/>
        <bands>
          <band label="Red"/>
          <band label="Green"/>
          <band label="Blue"/>
        </bands>
        <data_type>uint8</data_type>
{extra}      </sensor>
      <sensor id="5" label="Cylindrical" type="cylindrical">
        <resolution width="{W}" height="{H}"/>
        <property name="layer_index" value="0"/>
        <calibration type="cylindrical" class="adjusted">
          <resolution width="{W}" height="{H}"/>
          <f>{num(W / (2 * math.pi))}</f>
        </calibration>
      </sensor>
      <sensor id="2" label="unknown" type="frame">
        <resolution width="1920" height="1080"/>
        <property name="layer_index" value="0"/>
        <bands>
          <band label="Red"/>
          <band label="Green"/>
          <band label="Blue"/>
        </bands>
        <data_type>uint8</data_type>
      </sensor>
    </sensors>
"""


def camera_xml(cam, v2, indent):
    pad = " " * indent
    attrs = f'id="{cam["id"]}" sensor_id="{cam["sensor"]}"'
    if v2 and cam["aligned"]:
        attrs += ' component_id="0"'
    attrs += f' label="{cam["label"]}"'
    if cam["enabled"] is not None:
        attrs += f' enabled="{cam["enabled"]}"'
    wc = designed_world_from_camera(cam)
    c = wc[:3, 3]
    noisy = c + np.array([0.031, -0.017, 0.022]) * (cam["id"] + 1)
    lines = [f"{pad}<camera {attrs}>"]
    if cam["aligned"]:
        t = internal_camera_transform(wc)
        lines.append(f"{pad}  <transform>{nums(t)}</transform>")
        lines.append(f"{pad}  <rotation_covariance>{nums(spd(cam['id'], 1e-7))}</rotation_covariance>")
        lines.append(f"{pad}  <location_covariance>{nums(spd(100 + cam['id'], 1e-5))}</location_covariance>")
    lines.append(f"{pad}  <orientation>1</orientation>")
    lines.append(
        f'{pad}  <reference x="{num(noisy[0])}" y="{num(noisy[1])}" z="{num(noisy[2])}" '
        f'yaw="{num(10.0 * cam["id"])}" pitch="0" roll="-0" enabled="true" rotation_enabled="false"/>')
    lines.append(f"{pad}</camera>")
    return "\n".join(lines) + "\n"


def cameras_xml(v2):
    out = '    <cameras next_id="9" next_group_id="1">\n'
    top = [c for c in CAMERAS if not c["group"]]
    grp = [c for c in CAMERAS if c["group"]]
    out += camera_xml(top[0], v2, 6)
    out += '      <group id="0" label="Group 1" type="folder">\n'
    for c in grp:
        out += camera_xml(c, v2, 8)
    out += "      </group>\n"
    for c in top[1:]:
        out += camera_xml(c, v2, 6)
    out += "    </cameras>\n"
    return out


def similarity_xml(indent, locked):
    pad = " " * indent
    return (f"{pad}<transform>\n"
            f'{pad}  <rotation locked="{locked}">{nums(R_CHUNK)}</rotation>\n'
            f'{pad}  <translation locked="{locked}">{nums(T_CHUNK)}</translation>\n'
            f'{pad}  <scale locked="true">{num(S_CHUNK)}</scale>\n'
            f"{pad}</transform>\n")


def region_xml(indent):
    pad = " " * indent
    return (f"{pad}<region>\n"
            f"{pad}  <center>{nums(R_CHUNK.T @ (np.zeros(3) - T_CHUNK) / S_CHUNK)}</center>\n"
            f"{pad}  <size>1.5 1.5 1.5</size>\n"
            f"{pad}  <R>{nums(R_CHUNK)}</R>\n"
            f"{pad}</region>\n")


TAIL = """    <markers next_id="1" next_group_id="0">
      <marker id="0" label="point 1">
        <reference x="0.10000000000000001" y="0.20000000000000001" z="0.050000000000000003" enabled="true"/>
      </marker>
    </markers>
"""

CRS = ('    <reference>LOCAL_CS["Local Coordinates (m)",LOCAL_DATUM["Local Datum",0],'
       'UNIT["metre",1,AUTHORITY["EPSG","9001"]]]</reference>\n')

SETTINGS_META = """    <settings>
      <property name="accuracy_tiepoints" value="1"/>
      <property name="accuracy_cameras" value="10"/>
      <property name="accuracy_cameras_ypr" value="10"/>
      <property name="accuracy_markers" value="0.0050000000000000001"/>
      <property name="accuracy_scalebars" value="0.001"/>
      <property name="accuracy_projections" value="0.5"/>
    </settings>
    <meta>
      <property name="AlignCameras/adaptive_fitting" value="false"/>
      <property name="AlignCameras/duration" value="1.25"/>
      <property name="MatchPhotos/downscale" value="1"/>
      <property name="MatchPhotos/keypoint_limit" value="40000"/>
      <property name="OptimizeCameras/fit_flags" value="f cx cy k1 k2 k3 p1 p2"/>
    </meta>
"""


def document_v1():
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<document version="1.5.0">\n'
            '  <chunk label="Chunk 1" enabled="true">\n'
            + sensors_xml(False) + cameras_xml(False) + TAIL
            + similarity_xml(4, "false") + CRS + region_xml(4) + SETTINGS_META
            + "  </chunk>\n</document>\n")


def document_v2():
    comp = ('    <components next_id="1" active_id="0">\n'
            '      <component id="0" label="Component 1">\n'
            + similarity_xml(8, "false") + region_xml(8)
            + "        <partition>\n"
            + "          <camera_ids>" + " ".join(str(c["id"]) for c in CAMERAS if c["aligned"]) + "</camera_ids>\n"
            + "        </partition>\n"
            + "      </component>\n"
            + "    </components>\n")
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<document version="2.0.0">\n'
            '  <chunk label="Chunk 1" enabled="true">\n'
            + sensors_xml(True) + comp + cameras_xml(True) + TAIL + CRS + SETTINGS_META
            + "  </chunk>\n</document>\n")


# ---------------------------------------------------------------- reader ----
def floats(text):
    return np.array([float(v) for v in text.split()])


def similarity_from(tr):
    """<transform> with optional <rotation>/<translation>/<scale> -> 4x4 (s*R | t), R, t, s."""
    r = floats(tr.find("rotation").text).reshape(3, 3) if tr.find("rotation") is not None else np.eye(3)
    t = floats(tr.find("translation").text) if tr.find("translation") is not None else np.zeros(3)
    s = float(tr.find("scale").text) if tr.find("scale") is not None else 1.0
    m = np.eye(4)
    m[:3, :3] = s * r
    m[:3, 3] = t
    return m, r, t, s


# ------------------------------------------------------- camera models ----
def metashape_polynomial(x, y, k, p1, p2):
    """Metashape's Brown polynomial (manual, appendix "Camera models"): P1 goes with r^2 + 2x^2."""
    r2 = x * x + y * y
    radial = 1 + k[0] * r2 + k[1] * r2 ** 2 + k[2] * r2 ** 3 + k[3] * r2 ** 4
    xp = x * radial + p1 * (r2 + 2 * x * x) + 2 * p2 * x * y
    yp = y * radial + p2 * (r2 + 2 * y * y) + 2 * p1 * x * y
    return xp, yp


def frame_project(X, c):
    """Frame camera: x = X/Z, y = Y/Z; u = w/2 + cx + x'f + x'B1 + y'B2, v = h/2 + cy + y'f."""
    x, y = X[0] / X[2], X[1] / X[2]
    xp, yp = metashape_polynomial(x, y, c["k"], c["p1"], c["p2"])
    return [c["w"] * 0.5 + c["cx"] + xp * c["f"] + xp * c["b1"] + yp * c["b2"], c["h"] * 0.5 + c["cy"] + yp * c["f"]]


def fisheye_project(X, c):
    """Fisheye camera: x0 = X/Z, y0 = Y/Z, r0 = |(x0, y0)|, (x, y) = (x0, y0) atan(r0)/r0, then the
    frame camera's polynomial and affine on (x, y)."""
    x0, y0 = X[0] / X[2], X[1] / X[2]
    r0 = math.hypot(x0, y0)
    scale = math.atan(r0) / r0 if r0 > 0 else 1.0
    xp, yp = metashape_polynomial(x0 * scale, y0 * scale, c["k"], c["p1"], c["p2"])
    return [c["w"] * 0.5 + c["cx"] + xp * c["f"] + xp * c["b1"] + yp * c["b2"], c["h"] * 0.5 + c["cy"] + yp * c["f"]]


def spherical_project(X, w, h):
    """Spherical camera (no calibration), as nerfstudio's metashape_utils.py reads it: its
    EQUIRECTANGULAR with fl_x = w/2, cx = w/2, fl_y = h, cy = h/2 on the camera's own axes, i.e.
    longitude atan2(X, Z), latitude atan2(-Y, |(X, Z)|), u = w/2 + w lon/(2 pi), v = h/2 - h lat/pi."""
    lon = math.atan2(X[0], X[2])
    lat = math.atan2(-X[1], math.hypot(X[0], X[2]))
    return [w / 2 + w * lon / (2 * math.pi), h / 2 - h * lat / math.pi]


# ---------------------------------------------------------------- reader ----
def read_expected(path):
    root = ET.parse(path).getroot()
    chunk = root.find("chunk")
    sensors = {}
    for s in chunk.find("sensors").findall("sensor"):
        cals = s.findall("calibration")
        adjusted = [c for c in cals if c.get("class") == "adjusted"]
        cal = adjusted[0] if adjusted else (cals[0] if cals else None)
        sensors[s.get("id")] = (s, cal)

    chunk_tr = chunk.find("transform")
    comps = {}
    if chunk.find("components") is not None:
        for c in chunk.find("components").findall("component"):
            if c.find("transform") is not None:
                comps[c.get("id")] = similarity_from(c.find("transform"))

    out = {}
    for cam in chunk.find("cameras").iter("camera"):
        label = cam.get("label")
        e = {"camera_id": int(cam.get("id")), "sensor_id": int(cam.get("sensor_id"))}
        s_el, cal = sensors[cam.get("sensor_id")]
        kind = s_el.get("type", "frame")
        if cam.get("enabled", "true") in ("false", "0"):
            e.update(usable=False, reason="disabled")
        elif cam.find("transform") is None:
            e.update(usable=False, reason="not_aligned")
        elif kind not in ("frame", "fisheye", "spherical"):
            e.update(usable=False, reason="sensor_type")
        elif cal is None and kind != "spherical":
            e.update(usable=False, reason="sensor_not_calibrated")
        else:
            e["usable"] = True
            e["reason"] = "ok"
        out[label] = e
        if not e["usable"]:
            continue

        if kind == "spherical":
            w = int(s_el.find("resolution").get("width"))
            h = int(s_el.find("resolution").get("height"))
            e.update(width=w, height=h, sensor_type=kind, cx=w / 2, cy=h / 2,
                     lens={"model": "equirectangular", "params": [-180.0, 180.0, -90.0, 90.0]})
            project = lambda X: spherical_project(X, w, h)
        else:
            w = int(cal.find("resolution").get("width"))
            h = int(cal.find("resolution").get("height"))
            get = lambda k: float(cal.find(k).text) if cal.find(k) is not None else 0.0
            c = dict(w=w, h=h, f=get("f"), cx=get("cx"), cy=get("cy"), b1=get("b1"), b2=get("b2"),
                     k=[get("k1"), get("k2"), get("k3"), get("k4")], p1=get("p1"), p2=get("p2"))
            e.update(width=w, height=h, sensor_type=kind, fx=c["f"] + c["b1"], fy=c["f"], skew=c["b2"],
                     cx=w / 2 + c["cx"], cy=h / 2 + c["cy"],
                     cx_pixel_center_zero=w / 2 + c["cx"] - 0.5, cy_pixel_center_zero=h / 2 + c["cy"] - 0.5)
            distorted = any(v != 0 for v in c["k"] + [c["p1"], c["p2"]])
            if kind == "fisheye" or distorted or c["b2"] != 0:
                e["lens"] = {"model": "metashape_" + kind,
                             "params": [c["f"], w / 2 + c["cx"] - 0.5, h / 2 + c["cy"] - 0.5, c["b1"], c["b2"]]
                             + c["k"] + [c["p1"], c["p2"]]}
            else:
                e["lens"] = None  # a pinhole: fx = f + b1, fy = f
            project = (lambda X, c=c: fisheye_project(X, c)) if kind == "fisheye" else (lambda X, c=c: frame_project(X, c))

        t_cam = floats(cam.find("transform").text).reshape(4, 4)   # row-major
        comp_id = cam.get("component_id")
        if comp_id is not None and comp_id in comps:
            sim, r, t, s = comps[comp_id]
        elif chunk_tr is not None:
            sim, r, t, s = similarity_from(chunk_tr)
        else:
            sim, r, t, s = np.eye(4), np.eye(3), np.zeros(3), 1.0
        m = sim @ t_cam                       # camera -> world, rotation block scaled by s
        wfc = np.eye(4)
        wfc[:3, :3] = m[:3, :3] / s           # = R @ R_cam
        wfc[:3, 3] = m[:3, 3]                 # = s * R @ c_cam + t
        view = np.eye(4)
        view[:3, :3] = wfc[:3, :3].T
        view[:3, 3] = -wfc[:3, :3].T @ wfc[:3, 3]
        e["camera_transform_xml"] = t_cam.tolist()
        e["world_from_camera"] = wfc.tolist()
        e["camera_from_world"] = view.tolist()
        e["camera_center_world"] = wfc[:3, 3].tolist()
        design = next(d for d in CAMERAS if d["label"] == label)
        projs = []
        for p in PROBE_POINTS + lens_probe_points(design):
            x = view @ np.array(p + [1.0])
            projs.append({"world": p, "depth": x[2], "pixel": project(x[:3])})
        e["projections"] = projs
    return out


def main():
    (HERE / "frames.xml").write_text(document_v1(), encoding="utf-8")
    (HERE / "frames_v2.xml").write_text(document_v2(), encoding="utf-8")

    cams = read_expected(HERE / "frames.xml")
    cams_v2 = read_expected(HERE / "frames_v2.xml")

    # independent check 1: both layouts give the same answer
    assert cams.keys() == cams_v2.keys()
    for k in cams:
        a, b = cams[k], cams_v2[k]
        assert a["usable"] == b["usable"] and a["reason"] == b["reason"], k
        if a["usable"]:
            assert np.allclose(a["world_from_camera"], b["world_from_camera"], atol=1e-12), k

    # independent check 2: the read-back poses are the designed ones
    for c in CAMERAS:
        e = cams[c["label"]]
        if not e["usable"]:
            continue
        d = designed_world_from_camera(c)
        got = np.array(e["world_from_camera"])
        assert np.allclose(got, d, atol=1e-12), (c["label"], got - d)
        assert abs(np.linalg.norm(d[:3, 3]) - DIST) < 1e-12
        r = got[:3, :3]
        assert np.allclose(r.T @ r, np.eye(3), atol=1e-12) and abs(np.linalg.det(r) - 1) < 1e-12
        # looking at the world origin: it projects onto the principal point (no roll needed)
        u, v = e["projections"][0]["pixel"]
        assert abs(u - e["cx"]) < 1e-9 and abs(v - e["cy"]) < 1e-9, (u, v)

    # independent check 3: each spherical pixel, sent back through nerfstudio's own ray for an
    # EQUIRECTANGULAR camera (cameras.py, _generate_rays_from_coords: theta = -pi (x - cx)/fx,
    # phi = pi (0.5 + (y - cy)/fy), direction (-sin theta sin phi, cos phi, -cos theta sin phi) in
    # OpenGL axes) with metashape_utils.py's fl_x = w/2, cx = w/2, fl_y = h, cy = h/2, is the
    # direction of the probe in the camera frame (OpenCV axes: y and z negated).
    for c in CAMERAS:
        e = cams[c["label"]]
        if not e["usable"] or e["sensor_type"] != "spherical":
            continue
        w, h = e["width"], e["height"]
        view = np.array(e["camera_from_world"])
        for probe in e["projections"]:
            x, y = probe["pixel"]
            theta = -math.pi * (x - w / 2) / (w / 2)
            phi = math.pi * (0.5 + (y - h / 2) / h)
            gl = np.array([-math.sin(theta) * math.sin(phi), math.cos(phi), -math.cos(theta) * math.sin(phi)])
            cv = gl * np.array([1.0, -1.0, -1.0])
            d = (view @ np.array(probe["world"] + [1.0]))[:3]
            assert np.allclose(cv, d / np.linalg.norm(d), atol=1e-12), (c["label"], probe)

    expected = {
        "source": "frames.xml (frames_v2.xml gives the same values)",
        "generated_by": "expected.py (numpy " + np.__version__ + ")",
        "conventions": {
            "pixel_coordinates": "x right, y down; the top-left pixel's centre is (0.5, 0.5) "
                                 "(Metashape/COLMAP/nerfstudio); *_pixel_center_zero fields give the "
                                 "OpenCV convention (top-left pixel centre at (0, 0)) = value - 0.5",
            "intrinsics": "fx = f + b1, fy = f, skew = b2, cx = width/2 + <cx>, cy = height/2 + <cy>, "
                          "from the calibration with class=\"adjusted\"",
            "camera_axes": "OpenCV: x right, y down, z forward (Metashape's camera frame)",
            "matrices": "row-major nested lists [row][col]; column vectors; world_from_camera maps "
                        "camera coordinates to world; camera_from_world is its inverse (the view matrix)",
            "world": "world = s * R @ p + t with the chunk transform (rotation R, translation t, scale s) "
                     "and p the chunk-internal coordinates in which <camera><transform> is written; "
                     "world_from_camera = [R @ Rc | s * R @ tc + t] for <camera><transform> = [Rc | tc]",
            "projections": "pixel = the sensor's Metashape camera model (frame_project, fisheye_project, "
                           "spherical_project in expected.py) of the world point, in the pixel coordinates "
                           "above; depth = z in camera coordinates",
            "lens": "zcheck's lens (model and parameters) the camera reads as; null for a pinhole. "
                    "metashape_frame/metashape_fisheye: f, cx, cy, b1, b2, k1..k4, p1, p2 with cx, cy "
                    "in the OpenCV convention (w/2 + <cx> - 0.5); equirectangular: longitude and "
                    "latitude ranges in degrees",
        },
        "chunk_transform": {
            "rotation": R_CHUNK.tolist(),
            "rotation_axis": AXIS.tolist(),
            "rotation_angle_deg": ANGLE_DEG,
            "translation": T_CHUNK.tolist(),
            "scale": S_CHUNK,
        },
        "usable_count": sum(1 for e in cams.values() if e["usable"]),
        "cameras": cams,
    }
    (HERE / "expected.json").write_text(json.dumps(expected, indent=2) + "\n", encoding="utf-8")
    print("wrote frames.xml, frames_v2.xml, expected.json;",
          {k: (v["usable"], v["reason"]) for k, v in cams.items()})


if __name__ == "__main__":
    main()
