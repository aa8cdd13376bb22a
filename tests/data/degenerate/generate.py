#!/usr/bin/env python3
"""Writes the degenerate-input corpus (tests/data/degenerate/): one file per case and the
manifest cases.json. Run it from anywhere after changing a case; the files are committed so
the tests need no Python. tests/app/degenerate_input_test.cpp reads every case (README.md)."""

import json
import math
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
cases = []


def write(name, data):
    path = os.path.join(HERE, name)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    mode = "wb" if isinstance(data, bytes) else "w"
    with open(path, mode) as f:
        f.write(data)


def case(kind, name, data, expect, note):
    """One case: `name` under the kind's folder holds `data`; the one-line message must
    contain `expect`."""
    rel = f"{kind}/{name}"
    write(rel, data)
    cases.append({"file": rel, "kind": kind, "expect": expect, "note": note})


def dumps(obj):
    """Indented when small; large ones on one line, to keep the corpus small."""
    text = json.dumps(obj, indent=1, allow_nan=True)
    return (text if len(text) < 4096 else json.dumps(obj, separators=(",", ":"), allow_nan=True)) + "\n"


# ---------------------------------------------------------------- geometry helpers
def loop(cx, cy, cz, r, n=40, turns=1.0, tilt=0.0, plane=1):
    """A loop of n points around (cx, cy, cz), `turns` times around: `plane` 0 horizontal (XZ),
    1 frontal (XY), 2 sagittal (YZ); `tilt` turns it about the z axis."""
    pts = []
    for i in range(n):
        a = 2 * math.pi * turns * i / n
        c, d = r * math.cos(a), r * math.sin(a)
        off = [(c, 0, d), (c, d, 0), (0, c, d)][plane]
        off = (off[0] * math.cos(tilt) - off[1] * math.sin(tilt), off[0] * math.sin(tilt) + off[1] * math.cos(tilt), off[2])
        pts.append([round(cx + off[0], 6), round(cy + off[1], 6), round(cz + off[2], 6)])
    return pts


def stroke(sid, points, kind="lobe", times=None):
    s = {"id": sid, "kind": kind, "hand": "right", "closed": False, "points": points}
    s["times"] = times if times is not None else [round(0.1 * i, 3) for i in range(len(points))]
    return s


def session(strokes=None, lobes=None, **extra):
    doc = {"format": "lobesketch-session", "version": 1, "source_recording": "", "seed": 1,
           "strokes": strokes or [], "lobes": lobes or [], "edits": [], "trees": []}
    doc.update(extra)
    return doc


def good_loops():
    """Three rings of one lobe, in the three planes through its centre."""
    return [stroke(1, loop(0.05, 1.4, -0.42, 0.15, n=120, plane=0)),
            stroke(2, loop(0.05, 1.4, -0.42, 0.15, n=120, plane=1)),
            stroke(3, loop(0.05, 1.4, -0.42, 0.15, n=120, plane=2))]


TRUNK = stroke(4, [[0.0, round(0.8 + 0.02 * i, 3), -0.4] for i in range(30)], kind="trunk")

# The session the stroke cases are applied to: one lobe of three loops and a trunk.
write("base-session.json", dumps(session(good_loops() + [TRUNK], [{"id": 1, "strokes": [1, 2, 3], "mesh": ""}])))

# ---------------------------------------------------------------- session documents
S = "session"


def bad_session(name, doc, expect, note):
    case(S, name, doc if isinstance(doc, str) else dumps(doc), expect, note)


def with_stroke(**fields):
    s = stroke(1, loop(0, 1.4, -0.4, 0.2))
    s.update(fields)
    return session([s], [{"id": 1, "strokes": [1], "mesh": ""}])


bad_session("empty.json", "", "not valid JSON", "an empty file")
bad_session("not-json.json", "lobes: [1, 2\n", "not valid JSON", "not JSON at all")
bad_session("binary-garbage.json", "\x00\x01\x02\xff", "not valid JSON", "bytes that are not text")
bad_session("array.json", "[1, 2, 3]\n", "not a session document (expected a JSON object)", "a JSON array")
bad_session("format-missing.json", {"version": 1}, "not a session document", "no format key")
bad_session("format-wrong.json", {"format": "lobesketch-species", "version": 1}, "not a session document",
            "another program's format")
bad_session("version-string.json", {"format": "lobesketch-session", "version": "1"}, "version: expected an integer",
            "version of the wrong type")
bad_session("version-unknown.json", session(version=99), "unsupported session version 99", "a newer version")
bad_session("version-zero.json", session(version=0), "unsupported session version 0", "version 0")
bad_session("version-wraps.json", session(version=4294967297), "unsupported session version 4294967297",
            "a version that wraps to 1 in 32 bits")
bad_session("version-fraction.json", session(version=1.5), "version: expected an integer", "a fractional version")
bad_session("seed-string.json", session(seed="7"), "seed: expected a non-negative integer", "seed of the wrong type")
bad_session("seed-negative.json", session(seed=-1), "seed: expected a non-negative integer", "a negative seed")
bad_session("source-recording-number.json", session(source_recording=5), "source_recording: expected a string",
            "source_recording of the wrong type")
bad_session("settings-array.json", session(settings=[]), "settings: expected an object", "settings of the wrong type")
bad_session("settings-unknown-key.json", session(settings={"colour": 1}), "settings: unknown key 'colour'",
            "a settings key this build does not know")
bad_session("settings-out-of-range.json", session(settings={"input": {"pinch_start_m": 5}}),
            "settings.input.pinch_start_m must be in (0, 0.1)", "a setting out of its range")
bad_session("strokes-object.json", session(strokes={"1": []}), "strokes: expected an array", "strokes of the wrong type")
bad_session("stroke-number.json", session(strokes=[5]), "strokes[0]: expected an object", "a stroke that is a number")
bad_session("stroke-id-string.json", with_stroke(id="1"), "strokes[0].id: expected an integer", "a stroke id string")
bad_session("stroke-id-fraction.json", with_stroke(id=1.5), "strokes[0].id: expected an integer",
            "a fractional stroke id")
bad_session("stroke-kind-unknown.json", with_stroke(kind="leaf"), "strokes[0].kind: unknown stroke kind 'leaf'",
            "a stroke kind this build does not know")
bad_session("stroke-kind-number.json", with_stroke(kind=1), "strokes[0].kind: expected a string",
            "a stroke kind of the wrong type")
bad_session("stroke-hand-wrong.json", with_stroke(hand="both"), "strokes[0].hand: expected \"left\" or \"right\"",
            "an unknown hand")
bad_session("stroke-closed-string.json", with_stroke(closed="yes"), "strokes[0].closed: expected true or false",
            "closed of the wrong type")
s = stroke(1, [])
del s["points"]
bad_session("stroke-points-missing.json", session([s]), "strokes[0].points: expected an array", "a stroke without points")
bad_session("stroke-points-empty.json", session([stroke(1, [])]), "strokes[0].points: 0 points, a stroke needs at least 2",
            "a stroke with 0 points")
bad_session("stroke-one-point.json", session([stroke(1, [[0, 1, 0]])]),
            "strokes[0].points: 1 point, a stroke needs at least 2", "a stroke with 1 point")
bad_session("stroke-point-2d.json", session([stroke(1, [[0, 1, 0], [0, 1], [0, 1, 1]])]),
            "strokes[0].points[1]: expected [x, y, z]", "a point with two coordinates")
bad_session("stroke-point-string.json", session([stroke(1, [[0, 1, 0], [0, "1", 0], [0, 1, 1]])]),
            "strokes[0].points[1]: expected [x, y, z]", "a coordinate that is a string")
bad_session("stroke-point-null.json", session([stroke(1, [[0, 1, 0], [0, None, 0], [0, 1, 1]])]),
            "strokes[0].points[1]: expected [x, y, z]", "a coordinate that is null (how JSON writers spell NaN)")
bad_session("stroke-times-mismatch.json", session([stroke(1, loop(0, 1, 0, 0.2), times=[0.0, 0.1])]),
            "strokes[0].times: expected one time per point", "fewer times than points")
bad_session("stroke-times-string.json", session([stroke(1, loop(0, 1, 0, 0.2, n=4), times=[0, 0.1, "x", 0.3])]),
            "strokes[0].times: expected numbers", "a time that is a string")
bad_session("stroke-nan-literal.json", dumps(session([stroke(1, [[0, 1, 0], [float("nan"), 1, 0], [0, 1, 1]])])),
            "not valid JSON", "NaN is not JSON")
bad_session("stroke-infinity-literal.json", dumps(session([stroke(1, [[0, 1, 0], [float("inf"), 1, 0], [0, 1, 1]])])),
            "not valid JSON", "Infinity is not JSON")
bad_session("stroke-coordinate-overflows-float.json", session([stroke(1, [[0, 1, 0], [0, 1e39, 0], [0, 1, 1]])]),
            "strokes[0].points[1]: not finite", "a coordinate beyond the float range")
bad_session("stroke-coordinate-1e300.json", session([stroke(1, [[0, 1, 0], [0, 1, 1e300], [0, 1, 1]])]),
            "strokes[0].points[1]: not finite", "a coordinate of 1e300")
bad_session("stroke-coordinate-beyond-1km.json", session([stroke(1, [[0, 1, 0], [5000, 1, 0], [0, 1, 1]])]),
            "strokes[0].points: point 1 lies 5000 m from the origin along an axis (limit 1000 m)",
            "a coordinate 5 km away")
bad_session("stroke-time-huge.json", dumps(session([stroke(1, [[0, 1, 0], [0, 1, 1]], times=[0, 1e999])])).replace("Infinity", "1e999"),
            "not valid JSON", "a time of 1e999, beyond every floating-point type")
bad_session("stroke-duplicate-id.json", session(good_loops()[:2] + [dict(good_loops()[2], id=1)]),
            "strokes[2].id: stroke id 1 is used twice", "two strokes with one id")
bad_session("lobes-object.json", session(good_loops(), lobes={"id": 1}), "lobes: expected an array", "lobes of the wrong type")
bad_session("lobe-number.json", session(good_loops(), [7]), "lobes[0]: expected an object", "a lobe that is a number")
bad_session("lobe-id-missing.json", session(good_loops(), [{"strokes": [1]}]), "lobes[0].id: expected an integer",
            "a lobe without an id")
bad_session("lobe-strokes-string.json", session(good_loops(), [{"id": 1, "strokes": "1,2,3"}]),
            "lobes[0].strokes: expected an array of ids", "stroke ids as a string")
bad_session("lobe-stroke-id-fraction.json", session(good_loops(), [{"id": 1, "strokes": [1, 2.5]}]),
            "lobes[0].strokes: expected integer ids", "a fractional stroke id in a lobe")
bad_session("lobe-duplicate-id.json", session(good_loops(), [{"id": 1, "strokes": [1, 2]}, {"id": 1, "strokes": [3]}]),
            "lobes[1].id: lobe id 1 is used twice", "two lobes with one id")
bad_session("lobe-mesh-number.json", session(good_loops(), [{"id": 1, "strokes": [1], "mesh": 3}]),
            "lobes[0].mesh: expected a file name", "a mesh file name of the wrong type")
bad_session("lobe-split-angle-range.json", session(good_loops(), [{"id": 1, "strokes": [1], "split_angle_deg": 0}]),
            "lobes[0].split_angle_deg: must be in [5, 180]", "a per-lobe setting out of range")
bad_session("lobe-leaves-per-node-huge.json", session(good_loops(), [{"id": 1, "strokes": [1], "leaves_per_node": 1e12}]),
            "lobes[0].leaves_per_node: expected an integer", "a per-lobe count that is huge")
tet = {"source": "t.obj", "positions": [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1], "triangles": [0, 2, 1, 0, 1, 3, 0, 3, 2]}
bad_session("lobe-model-three-triangles.json", session([], [{"id": 1, "strokes": [], "model": tet}]),
            "lobes[0].model.triangles: a closed mesh needs at least 4 triangles", "a mesh lobe that is not closed")
bad_session("lobe-model-index-range.json",
            session([], [{"id": 1, "strokes": [], "model": dict(tet, triangles=[0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 9])}]),
            "lobes[0].model.triangles: vertex index 9 out of range", "a mesh lobe with a vertex index out of range")
bad_session("lobe-model-huge-coordinate.json",
            session([], [{"id": 1, "strokes": [], "model": dict(tet, positions=[0, 0, 0, 1, 0, 0, 0, 1e6, 0, 0, 0, 1],
                                                                   triangles=[0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3])}]),
            "lobes[0].model.positions: a coordinate is not finite or beyond 1 km", "a mesh lobe 1000 km tall")
bad_session("edits-object.json", session(edits={}), "edits: expected an array", "edits of the wrong type")
bad_session("edit-type-missing.json", session(edits=[{"id": 1, "target": 1}]), "edits[0].type: expected a string",
            "an edit without a type")
# Edit operations: refused when the session loads, naming the field (docs/session-format.md,
# "Edit operations"); only what depends on the document (a target that is gone, a pick that
# no longer holds) is left to re-application, which skips the edit with a warning. These
# are refused whatever the document holds, so the sessions hold nothing else.


def edit(kind, target=1, **params):
    return {"id": 1, "type": kind, "target": target,
            "params": dict({"hand": "right", "path": [[0.05, 1.55, -0.42, 1.0], [0.1, 1.55, -0.42, 1.5]]}, **params)}


bad_session("edit-type-unknown.json", session(edits=[edit("drag:pull-lobe")]),
            'edits[0].type: unknown edit type "drag:pull-lobe"', "an edit of a type no tool makes")
bad_session("edit-path-point-short.json",
            session(edits=[edit("drag:move-lobe", path=[[0.05, 1.55, -0.42, 1.0], [0.06, 1.55, -0.42, 1.1],
                                                                           [0.1, 1.55]])]),
            "edits[0].params.path[2]: expected [x, y, z] or [x, y, z, t] numbers", "a path point of two numbers")
bad_session("edit-path-empty.json", session(edits=[edit("drag:deform-lobe", path=[])]),
            "edits[0].params.path: expected a non-empty array", "a pinch deform without a path")
bad_session("edit-path-far.json",
            session(edits=[edit("drag:move-lobe", path=[[0.05, 1.55, -0.42, 1.0], [5000.0, 1.55, -0.42, 1.5]])]),
            "edits[0].params.path[1]: a coordinate is not finite or beyond 1 km", "a move dragged 5 km away")
bad_session("edit-rotate-no-centre.json", session(edits=[edit("drag:rotate-lobe", strokes=[1, 2, 3])]),
            "edits[0].params.centre: missing", "a rotation without the centre it turns about")
bad_session("edit-hand-missing.json",
            session(edits=[{"id": 1, "type": "drag:deform-lobe", "target": 1,
                                                "params": {"path": [[0.05, 1.55, -0.42, 1.0]]}}]),
            'edits[0].params.hand: expected "left" or "right"', "an edit without the hand that made it")
bad_session("edit-params-unknown-key.json", session(edits=[edit("drag:edit-stroke", pick_distance=0.03)]),
            "edits[0].params: unknown key 'pick_distance' for drag:edit-stroke", "a stroke edit with a misspelt key")
bad_session("edit-pick-distance-negative.json",
            session(edits=[edit("drag:edit-stroke", pick_distance_m=-0.03)]),
            "edits[0].params.pick_distance_m: expected a positive number", "a stroke edit with a negative pick distance")
bad_session("edit-strokes-not-ids.json", session(edits=[edit("drag:move-lobe", strokes=["1"])]),
            "edits[0].params.strokes: expected integer ids", "a move whose stroke list holds a string")
bad_session("trees-transform-short.json", session(trees=[{"id": 1, "transform": [1, 0, 0, 0]}]),
            "trees[0].transform: expected 16 numbers", "a transform of 4 numbers")
bad_session("tree-lobes-string.json", session(trees=[{"id": 1, "lobes": "all"}]),
            "trees[0].lobes: expected an array of ids", "tree lobes of the wrong type")
bad_session("lobes-too-many.json", session(lobes=[0] * 1001), "lobes: 1001 lobes, more than the 1000 a session may hold",
            "more lobes than a session may hold")
bad_session("trees-too-many.json", session(trees=[0] * 1001), "trees: 1001 trees, more than the 1000 a session may hold",
            "more trees than a session may hold")
bad_session("edits-too-many.json", session(edits=[0] * 20001),
            "edits: 20001 edits, more than the 20000 a session may hold", "more edits than a session may hold")

# ------------------------------------------- sessions that load, but whose lobes refuse strokes
L = "lobes"


def lobe_session(name, strokes, lobes, expect, note):
    case(L, name, dumps(session(strokes, lobes)), expect, note)


lobe_session("stroke-two-points.json", good_loops() + [stroke(5, [[0, 1.4, -0.2], [0.1, 1.5, -0.2]])],
             [{"id": 1, "strokes": [1, 2, 3, 5]}], "stroke has 2 points, at least 4 are needed",
             "a lobe stroke of 2 points (a session may hold it; the lobe leaves it out)")
lobe_session("collinear-stroke.json", good_loops() + [stroke(5, [[0.01 * i, 1.4, -0.2] for i in range(20)])],
             [{"id": 1, "strokes": [1, 2, 3, 5]}], "all points lie on one straight line", "a straight lobe stroke")
lobe_session("collinear-lobe.json", [stroke(1, [[0.01 * i, 1.4, -0.2] for i in range(20)]),
                                     stroke(2, [[0.01 * i, 1.4, -0.2] for i in range(5, 30)])],
             [{"id": 1, "strokes": [1, 2]}], "all points lie on one straight line", "a lobe of straight strokes only")
lobe_session("identical-points.json", good_loops() + [stroke(5, [[0.1, 1.4, -0.2]] * 10)],
             [{"id": 1, "strokes": [1, 2, 3, 5]}], "all points coincide", "a lobe stroke whose points are all one")
lobe_session("unknown-stroke-ids.json", good_loops(), [{"id": 1, "strokes": [1, 2, 3, 99]}], "stroke 99 is missing",
             "a lobe that lists a stroke the session does not hold")
# A stroke twice round one loop is closed where its ends cross, to one loop (lobe-strokes.md):
# that is no error. Three times round, closing leaves the same loop twice.
lobe_session("loop-three-times.json", good_loops() + [stroke(5, loop(0.05, 1.4, -0.42, 0.15, n=360, turns=3.0, tilt=0.5, plane=0))],
             [{"id": 1, "strokes": [1, 2, 3, 5]}], "lobe stroke 5 retraces itself (the same loop twice",
             "a stroke three times round one loop: closing leaves the same loop twice")
lobe_session("duplicated-stroke.json", good_loops() + [dict(good_loops()[1], id=5)],
             [{"id": 1, "strokes": [1, 2, 3, 5]}], "lobe stroke 5 retraces lobe stroke 2", "the same stroke twice under two ids")
case(L, "huge-lobe.json", dumps(session([stroke(i + 1, loop(0, 2.4, -0.4, 2.2, n=90, plane=i)) for i in range(3)],
                                         [{"id": 1, "strokes": [1, 2, 3]}],
                                         settings={"lobes": {"edge_length_m": 0.005}})),
     "more than the 4000000 allowed", "a lobe 4.4 m across at 5 mm attractor spacing: too many triangles")

big_tet = {"source": "big.obj", "positions": [0, 0, 0, 100, 0, 0, 0, 100, 0, 0, 0, 100],
           "triangles": [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]}
case(L, "huge-mesh-lobe.json", dumps(session([], [{"id": 1, "strokes": [], "model": big_tet}])),
     "lobe 1: remesh_isotropic:", "a lobe made from a mesh 100 m across, remeshed to 3 cm: too many triangles")

# ---------------------------------------------------- strokes applied live (SessionBuilder)
# Numbers that JSON cannot hold are written as the strings "nan", "inf" and "-inf".
K = "stroke"


def live(name, kind, points, expect, note, times=None):
    obj = {"kind": kind, "points": points}
    if times is not None:
        obj["times"] = times
    case(K, name, dumps(obj), expect, note)


live("empty.json", "lobe", [], "0 points, a stroke needs at least 2", "a stroke with no points")
live("one-point.json", "lobe", [[0, 1.4, -0.2]], "1 point, a stroke needs at least 2", "a stroke of one point")
live("two-points.json", "lobe", [[0, 1.4, -0.2], [0.1, 1.5, -0.2]], "too short (14.1 cm, 2 points; need 3.0 cm and 4 points)",
     "a stroke of two points")
live("too-short.json", "lobe", [[0, 1.4, -0.2], [0.005, 1.405, -0.2], [0.01, 1.4, -0.2], [0.012, 1.41, -0.2]],
     "too short", "a stroke under 3 cm")
live("collinear.json", "lobe", [[0.01 * i, 1.4 + 0.005 * i, -0.2] for i in range(30)],
     "all its points lie on one straight line, so it cannot bound a lobe", "a straight lobe stroke")
live("identical.json", "lobe", [[0.1, 1.4, -0.2]] * 30, "all its points lie at one place (zero length)",
     "a lobe stroke whose points are all one")
live("identical-trunk.json", "trunk", [[0.1, 1.0, -0.2]] * 30, "all its points lie at one place (zero length)",
     "a trunk stroke whose points are all one")
live("nan.json", "lobe", loop(0, 1.4, -0.2, 0.2)[:2] + [["nan", 1.4, -0.2]] + loop(0, 1.4, -0.2, 0.2)[3:],
     "point 2 has a coordinate that is not finite", "a NaN coordinate")
live("inf.json", "trunk", [[0, 1, 0], [0, "inf", 0], [0, 2, 0]], "point 1 has a coordinate that is not finite",
     "an infinite coordinate on a trunk stroke")
live("huge.json", "lobe", loop(0, 1.4, -0.2, 0.2)[:5] + [[0, 1.4, 5000.0]] + loop(0, 1.4, -0.2, 0.2)[6:],
     "point 5 lies 5000 m from the origin along an axis (limit 1000 m)", "a point 5 km away")
live("huge-loop.json", "lobe", loop(0, 1.4, -0.2, 2000.0), "lies 2000 m from the origin", "a loop 4 km across")
live("nan-time.json", "lobe", loop(0, 1.4, -0.2, 0.2, n=6), "point 3 has a time that is not finite", "a NaN time",
     times=[0, 0.1, 0.2, "nan", 0.4, 0.5])

# ---------------------------------------------------------------- settings files
T = "settings"


def bad_settings(name, obj, expect, note):
    case(T, name, obj if isinstance(obj, str) else dumps(obj), expect, note)


bad_settings("empty.json", "", "not valid JSON", "an empty file")
bad_settings("not-json.json", "growth: {max_nodes: 5}\n", "not valid JSON", "YAML, not JSON")
bad_settings("array.json", [1, 2], "settings: expected an object", "a JSON array")
bad_settings("unknown-section.json", {"trunk": {}}, "settings: unknown key 'trunk'", "a section this build does not know")
bad_settings("unknown-key.json", {"growth": {"max_node": 5}}, "settings.growth: unknown key 'max_node'", "a misspelt key")
bad_settings("section-wrong-type.json", {"growth": 5}, "settings.growth: expected an object", "a section that is a number")
bad_settings("number-as-string.json", {"growth": {"max_iterations": "64"}}, "settings.growth.max_iterations: expected a number",
             "a number written as a string")
bad_settings("integer-fraction.json", {"growth": {"max_iterations": 1.5}},
             "settings.growth.max_iterations: expected an integer in [-1e9, 1e9]", "a fractional count")
bad_settings("integer-huge.json", {"growth": {"max_nodes": 1e300}},
             "settings.growth.max_nodes: expected an integer in [-1e9, 1e9]", "a count of 1e300")
bad_settings("max-nodes-range.json", {"growth": {"max_nodes": 10}}, "settings.growth.max_nodes must be in [100, 5000000]",
             "too few nodes")
bad_settings("max-iterations-range.json", {"growth": {"max_iterations": 100000}},
             "settings.growth.max_iterations must be in [1, 1000]", "too many iterations")
bad_settings("remesh-iterations-range.json", {"lobes": {"remesh_iterations": 1000}},
             "settings.lobes.remesh_iterations must be in [0, 20]", "too many remeshing rounds")
bad_settings("edge-length-range.json", {"lobes": {"edge_length_m": 0.0001}},
             "settings.lobes.edge_length_m must be in [0.005, 0.5]", "a 0.1 mm attractor spacing")
bad_settings("radial-segments-range.json", {"branches": {"radial_segments": 100000}},
             "settings.branches.radial_segments must be in [3, 64]", "too many radial segments")
bad_settings("lod-count-range.json", {"branches": {"lod_count": 0}}, "settings.branches.lod_count must be in [1, 6]",
             "no level of detail")
bad_settings("leaves-per-node-range.json", {"leaves": {"per_node": 1000}}, "settings.leaves.per_node must be in [0, 64]",
             "too many leaves per node")
bad_settings("bark-color-short.json", {"branches": {"bark_color": [0.1, 0.2]}},
             "settings.branches.bark_color: expected [r, g, b]", "a colour of two components")
bad_settings("leaf-shape-unknown.json", {"leaves": {"shape": "maple"}}, "settings.leaves.shape must be",
             "a leaf shape this build does not have")
bad_settings("subtree-weights-too-many.json", {"growth": {"subtree_weights": {f"s{i}": 1 for i in range(257)}}},
             "settings.growth.subtree_weights: too many entries", "more subtree weights than allowed")
bad_settings("subtree-weight-negative.json", {"growth": {"subtree_weights": {"fork": -1}}},
             "settings.growth.subtree_weights.fork: must be in [0, 1e6]", "a negative weight")
bad_settings("filter-wrong-type.json", {"input": {"filter": [1, 2, 3]}}, "settings.input.filter: expected an object",
             "a filter that is an array")
bad_settings("pinch-release-below-start.json", {"input": {"pinch_start_m": 0.02, "pinch_release_m": 0.01}},
             "settings.input.pinch_release_m must be in (pinch_start_m, 0.2)", "settings that contradict each other")
bad_settings("session-with-bad-settings.json", {"format": "lobesketch-session", "version": 1,
                                                "settings": {"leaves": {"length_m": -1}}},
             "settings.leaves.length_m must be in [0.002, 1]", "a session document whose settings are out of range")

# ---------------------------------------------------------------- species presets
P = "species"


def species(**extra):
    obj = {"format": "lobesketch-species", "version": 1, "name": "test", "description": "a test preset"}
    obj.update(extra)
    return obj


def bad_species(name, obj, expect, note):
    case(P, name, obj if isinstance(obj, str) else dumps(obj), expect, note)


bad_species("empty.json", "", "not valid JSON", "an empty file")
bad_species("not-json.json", "{\"format\": ", "not valid JSON", "a file cut short")
bad_species("format-wrong.json", dict(species(), format="lobesketch-session"), "not a species preset",
            "a session document given as a preset")
bad_species("version-unknown.json", species(version=2), "unsupported species preset version", "a newer version")
bad_species("version-string.json", species(version="1"), "unsupported species preset version", "version of the wrong type")
bad_species("unknown-key.json", species(colour="green"), "unknown key 'colour'", "a key this build does not know")
bad_species("name-missing.json", {k: v for k, v in species().items() if k != "name"},
            "\"name\" must be a name of 1 to 64 characters", "no name")
bad_species("name-too-long.json", species(name="x" * 65), "\"name\" must be a name of 1 to 64 characters",
            "a 65-character name")
bad_species("description-number.json", species(description=5), "\"description\" must be a string",
            "a description that is a number")
bad_species("growth-array.json", species(growth=[1]), "\"growth\" must be an object", "a section that is an array")
bad_species("growth-species.json", species(growth={"species": "oak"}), "growth.species is the preset's own name",
            "a preset naming another species")
bad_species("growth-unknown-key.json", species(growth={"max_node": 5}), "growth: unknown key 'max_node'", "a misspelt key")
bad_species("max-nodes-range.json", species(growth={"max_nodes": 1}), "settings.growth.max_nodes must be in [100, 5000000]",
            "a value out of range")
bad_species("per-node-string.json", species(leaves={"per_node": "4"}), "leaves.per_node: expected a number",
            "a number written as a string")
bad_species("split-angle-huge.json", species(growth={"split_angle_deg": 1e308}),
            "settings.growth.split_angle_deg must be in [5, 180]", "an angle of 1e308 degrees")

# ---------------------------------------------------------------- recordings
R = "recording"
MAGIC = b"LOBEREC\x1a"
SYNC = struct.pack("<I", 0x1E524CFE)


def binary_header(header=None, major=1, minor=0):
    js = json.dumps(header if header is not None else
                    {"created": "", "device": "none", "nominal_rate_hz": 90.0, "source": "degenerate", "space": "stage",
                     "units": "m"}, sort_keys=True, separators=(",", ":")).encode()
    return MAGIC + struct.pack("<HHI", major, minor, len(js)) + js + struct.pack("<I", zlib.crc32(js))


def record(rtype, payload):
    body = struct.pack("<BI", rtype, len(payload)) + payload
    return SYNC + body + struct.pack("<I", zlib.crc32(body))


def joint(pos):
    return struct.pack("<fff", *pos) + struct.pack("<hhhh", 32767, 0, 0, 0) + struct.pack("<H", 800) + bytes([15])


def frame(t, left=None):
    p = struct.pack("<d", t) + bytes([0])
    if left is None:
        p += bytes([0])
    else:
        p += bytes([1]) + b"".join(joint(left(j)) for j in range(26))
    return p + bytes([0])


nan = float("nan")
case(R, "empty.lrec", b"", "empty file", "an empty file")
case(R, "wrong-magic.lrec", b"NOTAREC\x1a" + b"\x01\x00\x00\x00" + b"\x00" * 32, "wrong magic bytes", "another format")
case(R, "truncated-header.lrec", MAGIC + b"\x01\x00", "truncated file header", "a file cut inside its header")
case(R, "unknown-version.lrec", binary_header(major=99), "unsupported recording version 99", "a newer major version")
case(R, "header-length-huge.lrec", MAGIC + struct.pack("<HHI", 1, 0, 0xFFFFFFF0) + b"{}", "truncated or corrupt header",
     "a header length of 4 GiB")
case(R, "units-cm.lrec", binary_header({"units": "cm"}) + record(1, frame(0.0, lambda j: (0, 1, 0))),
     "units 'cm' are not supported", "centimetres")
case(R, "nan-joints.lrec",
     binary_header() + b"".join(record(1, frame(0.011 * i, lambda j: (nan, 1.0, -0.3))) for i in range(5)),
     "no usable frames", "every frame has NaN joint positions")
case(R, "absurd-joints.lrec",
     binary_header() + b"".join(record(1, frame(0.011 * i, lambda j: (0.0, 5000.0, -0.3))) for i in range(5)),
     "no usable frames", "every joint 5 km up")
case(R, "truncated-records.lrec", binary_header() + record(1, frame(0.0, lambda j: (0.01 * j, 1.0, -0.3)))[:40],
     "no usable frames", "the only frame cut short")
case(R, "bad-crc.lrec", binary_header() + record(1, frame(0.0, lambda j: (0.01 * j, 1.0, -0.3)))[:-1] + b"\x00",
     "no usable frames", "the only frame with a wrong checksum")

TEXT_HEAD = "lobesketch-recording-text 1\nheader {\"units\":\"m\"}\n"


def text_hand(pos):
    return " ".join(f"{pos[0]} {pos[1]} {pos[2]} 1 0 0 0 0.008 15" for _ in range(26))


case(R, "text-version-unknown.txt", "lobesketch-recording-text 7\nframe 0 head - left - right -\n",
     "unsupported recording version 7", "a newer text version")
case(R, "text-version-garbage.txt", "lobesketch-recording-text one\n", "bad version line", "a version that is not a number")
case(R, "text-nan-joints.txt", TEXT_HEAD + "".join(f"frame {0.011 * i:.3f} head - left {text_hand(('nan', 1, -0.3))} right -\n"
                                                   for i in range(4)),
     "no usable frames", "every frame has NaN joints")
case(R, "text-inf-joints.txt", TEXT_HEAD + "".join(f"frame {0.011 * i:.3f} head - left - right {text_hand((0, 'inf', -0.3))}\n"
                                                   for i in range(4)),
     "no usable frames", "every frame has infinite joints")
case(R, "text-short-hand.txt", TEXT_HEAD + "frame 0 head - left 1 2 3 right -\n", "no usable frames",
     "a hand with 3 numbers instead of 234")
case(R, "text-truncated.txt", TEXT_HEAD + "frame 0 head - left " + text_hand((0, 1, -0.3))[:200], "no usable frames",
     "the only frame cut short")
case(R, "text-units-mm.txt", "lobesketch-recording-text 1\nheader {\"units\":\"mm\"}\nframe 0 head - left - right -\n",
     "units 'mm' are not supported", "millimetres")
case(R, "text-no-frames.txt", TEXT_HEAD + "# nothing else\n", "no usable frames", "a header and nothing else")

# ---------------------------------------------------------------- meshes
M = "mesh"
case(M, "empty.obj", "", "empty file", "an empty OBJ")
case(M, "no-faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no face", "vertices and no face")
case(M, "nan-vertex.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "line 2: vertex 1 has a non-finite coordinate", "a NaN coordinate")
case(M, "index-out-of-range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "vertex index 9 out of range", "a face index beyond the vertices")
case(M, "two-vertex-face.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", "face with 2 vertices (at least 3 needed)", "a face of two vertices")
case(M, "huge-counts.off", "OFF\n1000000000 1000000000 0\n0 0 0\n", "declares 1000000000 vertices (limit 10000000)", "counts far beyond the file")
case(M, "truncated.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                          "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\x00\x00",
     "element 'vertex' declares 3 entries, more than the file's 2 bytes of data can hold", "a binary PLY cut inside its vertices")

# ---------------------------------------------------------------- meshes made into lobes
# Read fine, but nothing closed can be made of them (`lobesketch lobes MESH`, lobe_from_model).
O = "model"


def obj(vs, fs):
    return "".join("v %g %g %g\n" % v for v in vs) + "".join("f %d %d %d\n" % tuple(i + 1 for i in f) for f in fs)


grid_v = [(i, j, 0) for j in range(5) for i in range(5)]
grid_f = [t for j in range(4) for i in range(4) for t in ((5 * j + i, 5 * j + i + 1, 5 * j + i + 6), (5 * j + i, 5 * j + i + 6, 5 * j + i + 5))]
case(O, "flat-triangle.obj", obj([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)]), "encloses no volume", "a single triangle")
case(O, "flat-grid.obj", obj(grid_v, grid_f), "encloses no volume", "a flat 4 × 4 grid: its border can only be capped by a copy of it")
case(O, "collinear-corners.obj", obj([(0, 0, 0), (1, 0, 0), (2, 0, 0), (3, 0, 0)], [(0, 1, 2), (1, 3, 2)]),
     "the mesh has no area", "triangles whose corners lie on one line")
case(O, "repeated-vertices-only.obj", obj([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 0, 1), (1, 2, 2)]),
     "no valid triangle left", "every triangle names a vertex twice")
case(O, "sliver-after-repair.obj",
     obj([(0, 0, 0), (0, 0, 1), (0, 1, 0), (0, 1, 1), (1, 0, 0), (1, 0, 1), (1, 1, 1), (1, 0, 0)],
         [(2, 7, 3), (2, 6, 7), (0, 6, 2), (0, 5, 4)]),
     "encloses no volume", "four faces whose repair leaves a closed sliver of no volume (found by fuzz/mesh_repair_fuzz.cpp)")

# A file left from a removed case would never be read: remove it.
listed = {c["file"] for c in cases}
for kind in sorted({c["kind"] for c in cases}):
    for name in sorted(os.listdir(os.path.join(HERE, kind))):
        if f"{kind}/{name}" not in listed:
            os.remove(os.path.join(HERE, kind, name))

with open(os.path.join(HERE, "cases.json"), "w") as f:
    json.dump({"about": "Degenerate inputs and the one-line message each must give (README.md).", "cases": cases}, f,
              indent=1)
    f.write("\n")
print(len(cases), "cases")
