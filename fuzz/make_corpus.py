#!/usr/bin/env python3
"""Regenerates the committed seed corpora in fuzz/corpus/<target>/ from the shipped files
(docs/fuzzing.md). Seeds stay small (a few KiB) so that libFuzzer's mutations run fast; the
big shipped files are cut down to their first frames, faces or records.

    fuzz/make_corpus.py [--lobesketch build/release/app/lobesketch]

With --lobesketch, the text-recording and session seeds are remade too (import-leap to the
text form, replay of a shipped recording); without it they are left as they are.
"""
import argparse
import json
import os
import pathlib
import shutil
import struct
import subprocess
import tempfile
import zlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "data"
OUT = ROOT / "fuzz" / "corpus"


def put(target, name, data):
    d = OUT / target
    d.mkdir(parents=True, exist_ok=True)
    (d / name).write_bytes(data if isinstance(data, bytes) else data.encode())


def js_value_end(s, i):
    """End of the JS/JSON value starting at s[i] (brackets, quoted strings)."""
    depth, quote = 0, None
    j = i
    while j < len(s):
        c = s[j]
        if quote:
            if c == "\\":
                j += 1
            elif c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c in "[{":
            depth += 1
        elif c in "]}":
            depth -= 1
            if depth == 0:
                return j + 1
        elif depth == 0 and c in ",":
            return j
        j += 1
    return j


def leap_seeds():
    for name in ["leap-grab", "leap-pinch"]:
        d = json.loads((SHARED / "real" / f"{name}.json").read_text())
        with_hands = [f for f in d["frames"] if f.get("hands")]
        for n in (1, 3):
            seed = {"frames": with_hands[len(with_hands) // 2:len(with_hands) // 2 + n], "metadata": d["metadata"]}
            put("import_leap", f"{name}-{n}.json", json.dumps(seed, separators=(",", ":")))
    put("import_leap", "empty-hands.json", '{"frames":[{"id":1,"timestamp":1000,"hands":[],"pointables":[]}],"metadata":{}}')


def webxr_seeds():
    s = (SHARED / "real" / "quest3-webxr-capture.min.js").read_text()
    i = s.index("frames:[") + len("frames:[")
    head = s[:i]
    rows = []
    while i < len(s) and s[i] != "]":
        j = js_value_end(s, i)
        rows.append(s[i:j])
        i = j + 1 if s[j:j + 1] == "," else j
    tail = "]};export{a as capture};"
    hands = [r for r in rows if len(r) > 1500]
    put("import_webxr", "controllers-2.js", head + ",".join(rows[:2]) + tail)
    put("import_webxr", "hands-1.js", head + ",".join(hands[:1]) + tail)
    put("import_webxr", "hands-3.js", head + ",".join(hands[len(hands) // 2:len(hands) // 2 + 3]) + tail)


def recording_binary_seeds():
    for name in ["pinch-edit", "table1-1lobe-5strokes"]:
        data = (ROOT / "recordings" / f"{name}.lrec").read_bytes()
        # header, then whole records only (a cut record is a seed of its own below)
        hlen = struct.unpack_from("<I", data, 12)[0]
        pos = 16 + hlen + 4
        records = 0
        while records < 3 and pos + 9 <= len(data):
            plen = struct.unpack_from("<I", data, pos + 5)[0]
            pos += 9 + plen + 4
            records += 1
        put("recording_binary", f"{name}-3records.lrec", data[:pos])
        put("recording_binary", f"{name}-cut.lrec", data[:pos - 100])
    # one frame, every event record of a recording with events, and an annotation
    data = (ROOT / "recordings" / "edit-stroke-transform.lrec").read_bytes()
    hlen = struct.unpack_from("<I", data, 12)[0]
    pos = 16 + hlen + 4
    out = data[:pos]
    frames = 0
    while pos + 9 <= len(data):
        rtype, plen = data[pos + 4], struct.unpack_from("<I", data, pos + 5)[0]
        if rtype != 1 or frames < 1:
            out += data[pos:pos + 9 + plen + 4]
            frames += rtype == 1
        pos += 9 + plen + 4
    note = struct.pack("<dH", 0.5, 12) + b"stroke_end 3"
    body = struct.pack("<BI", 3, len(note)) + note
    out += struct.pack("<I", 0x1E524CFE) + body + struct.pack("<I", zlib.crc32(body))
    put("recording_binary", "events-annotation.lrec", out)


def mesh_seeds():
    tet_v = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
    tet_f = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    # OBJ: the first faces of a shipped model, with the vertices they use, and the forms of
    # obj statements the reader knows
    for model, nf in [("spot", 40), ("cow", 40)]:
        lines = (SHARED / "models" / f"{model}.obj").read_text().splitlines()
        verts = [l for l in lines if l.startswith("v ")]
        faces = [l.split()[1:] for l in lines if l.startswith("f ")][:nf]
        used = sorted({int(t.split("/")[0]) for f in faces for t in f})
        remap = {v: k + 1 for k, v in enumerate(used)}
        out = [verts[v - 1] for v in used]
        out += ["f " + " ".join(str(remap[int(t.split("/")[0])]) for t in f) for f in faces]
        put("mesh_obj", f"{model}-{nf}faces.obj", "\n".join(out) + "\n")
    put("mesh_obj", "forms.obj",
        "# comment\no tet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\n"
        "f 1/1/1 3/1/1 2/1/1\nf -4//1 -3//1 -1//1\nf 1/1 4/1 3/1\nf 2 3 4\nl 1 2 3\ng x\ns off\nusemtl m\n")
    put("mesh_obj", "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nf 1 2 3 4\nf 1 2 5\r\n")
    # PLY
    hdr = "ply\nformat {fmt} 1.0\ncomment seed\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n" \
          "element face 4\nproperty list uchar int vertex_indices\nelement edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
    body = "".join(f"{x} {y} {z}\n" for x, y, z in tet_v) + "".join(f"3 {a} {b} {c}\n" for a, b, c in tet_f) + "0 1\n"
    put("mesh_ply", "tet-ascii.ply", hdr.format(fmt="ascii") + body)
    for fmt, e in [("binary_little_endian", "<"), ("binary_big_endian", ">")]:
        b = b"".join(struct.pack(e + "fff", *v) for v in tet_v)
        b += b"".join(struct.pack(e + "Biii", 3, *f) for f in tet_f) + struct.pack(e + "ii", 0, 1)
        put("mesh_ply", f"tet-{fmt}.ply", hdr.format(fmt=fmt).encode() + b)
    hdr2 = "ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n" \
           "property double z\nproperty uchar red\nelement face 2\nproperty list ushort uint vertex_index\n" \
           "property float quality\nelement other 1\nproperty list int short stuff\nend_header\n"
    b = b"".join(struct.pack("<dddB", *v, 7) for v in tet_v)
    b += struct.pack("<HIIIf", 3, 0, 1, 2, 0.5) + struct.pack("<HIIIIf", 4, 0, 1, 2, 3, 0.5)
    b += struct.pack("<ihh", 2, 1, 2)
    put("mesh_ply", "types.ply", hdr2.encode() + b)
    # OFF
    off = "OFF\n4 4 6\n" + "".join(f"{x} {y} {z}\n" for x, y, z in tet_v) + "".join(f"3 {a} {b} {c}\n" for a, b, c in tet_f)
    put("mesh_off", "tet.off", off)
    put("mesh_off", "quad-color.off", "COFF\n# comment\n5 2 0\n0 0 0 255 0 0 255\n1 0 0 0 0 0 255\n1 1 0 0 0 0 255\n"
        "0 1 0 0 0 0 255\n0.5 0.5 1 0 0 0 255\n4 0 1 2 3 255 0 0\n3 0 1 4\n")
    put("mesh_off", "one-line.off", "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")


def species_seeds():
    for p in sorted((ROOT / "growth" / "data" / "species").glob("*.json")):
        put("species", p.name, p.read_bytes())


def text_recording_seeds(lobesketch):
    hand = " ".join("0.%d 1.%d -0.3 1 0 0 0 0.01 15" % (j, j) for j in range(26))
    put("recording_text", "handwritten.txt",
        "lobesketch-recording-text 1\n"
        'header {"created":"","device":"none","nominal_rate_hz":90.0,"source":"hand-written","space":"stage","units":"m"}\n'
        "# comment\n\n"
        f"frame 0 head - left - right {hand}\n"
        f"frame 0.011 head 0 1.6 0 1 0 0 0 left {hand} right -\n"
        "event 0.25 key 32 1\nevent 0.3 mouse_button 0 1\nevent 0.3 mouse_move 412.5 300\nevent 0.4 wheel -1\n"
        "event 0.45 setting 1 0 25\nevent 0.46 setting 5 2 1\nnote 0.5 stroke_end id=3 \\n\\x41\\\\\n")
    put("recording_text", "events-only.txt", "lobesketch-recording-text 1.0\r\nevent 0 key 65 1\r\nevent 0.1 key 65 0\r\n")
    if not lobesketch:
        return
    with tempfile.TemporaryDirectory() as tmp:
        src = OUT / "import_leap" / "leap-pinch-3.json"
        subprocess.run([lobesketch, "import-leap", str(src), "-o", f"{tmp}/leap.txt"], check=True, capture_output=True)
        put("recording_text", "import-leap-3frames.txt", pathlib.Path(f"{tmp}/leap.txt").read_bytes())


HANDWRITTEN_SESSION = {
    "format": "lobesketch-session", "version": 1, "source_recording": "demo.lrec", "seed": 7,
    "settings": {"input": {"pinch_start_m": 0.008}, "lobes": {"edge_length_m": 0.03, "remesh_iterations": 3},
                 "growth": {"species": "conifer", "split_angle_deg": 25}, "branches": {}, "leaves": {}},
    "strokes": [{"id": 1, "kind": "lobe", "hand": "right", "closed": False,
                 "points": [[0.1, 1.2, -0.5], [0.12, 1.25, -0.5], [0.15, 1.3, -0.48], [0.1, 1.2, -0.5]],
                 "times": [3.5, 3.6, 3.7, 3.8]},
                {"id": 2, "kind": "trunk", "hand": "left", "closed": False,
                 "points": [[0, 0, -0.5], [0, 0.5, -0.5]], "times": [5.0, 5.5]}],
    "lobes": [{"id": 1, "strokes": [1], "mesh": "lobes/lobe_1.ply", "split_angle_deg": 40, "species": "willow"}],
    "edits": [{"id": 1, "type": "drag:edit-stroke", "target": 1,
               "params": {"hand": "right", "path": [[0.1, 1.2, -0.5, 4.0], [0.1, 1.3, -0.5, 4.2]],
                          "pick_distance_m": 0.03, "half_length_m": 0.08, "other_tip": [0.2, 1.2, -0.5]}},
              {"id": 2, "type": "drag:rotate-lobe", "target": 1,
               "params": {"hand": "right", "path": [[0.1, 1.2, -0.5, 6.0], [0.2, 1.2, -0.5, 6.5]],
                          "centre": [0.05, 1.4, -0.42], "strokes": [1]}}],
    "trees": [{"id": 1, "transform": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5, 0, 0, 1], "seed": 3, "lobes": []}],
}


def session_seeds(lobesketch):
    put("document", "handwritten.json", json.dumps(HANDWRITTEN_SESSION, indent=1))
    put("settings", "handwritten-session.json", json.dumps(HANDWRITTEN_SESSION, indent=1))
    put("settings", "partial.json", '{"growth": {"split_angle_deg": 20}, "lobes": {"edge_length_m": 0.02}}')
    if not lobesketch:
        return
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([lobesketch, "replay", str(ROOT / "recordings" / "edit-stroke-transform.lrec"), "-o", tmp],
                       check=True, capture_output=True)
        doc = json.loads(pathlib.Path(f"{tmp}/session.json").read_text())
    # few strokes, few points: the structure is what matters
    for s in doc["strokes"]:
        s["points"], s["times"] = s["points"][:4], s["times"][:4]
    doc["strokes"] = doc["strokes"][:3]
    for e in doc["edits"]:
        if "path" in e["params"]:
            e["params"]["path"] = e["params"]["path"][:3]
    doc["source_recording"] = "recordings/edit-stroke-transform.lrec"
    put("document", "replay-edit-stroke-transform.json", json.dumps(doc, indent=1))
    put("settings", "session.json", json.dumps(doc, indent=1))
    put("settings", "settings.json", json.dumps(doc["settings"], indent=1))


def desktop_script_seeds():
    for name, src in [("every-tool.script", "desktop_every_tool.script"), ("save.script", "desktop_save.script")]:
        put("desktop_script", name, (ROOT / "tests" / "data" / src).read_bytes())
    put("desktop_script", "every-command.script",
        "# every command and macro once\n0 move 320 180\n1 down left\n2 up left\n3 wheel -2\n4 key L\n"
        "5 press z\n6 release z\n7 ui draw-lobe\n8 set split-angle 35\n9 set leaves 4 lobe 1\n"
        "10 import models/cow.obj 0.8\n11 wait\n12 mark after-import\n13 circle 320 200 60 24\n"
        "40 line 100 100 300 120 12 right\n60 circle 200 200 30 8 none\n80 quit\n")


def scenario_seeds():
    for p in sorted((ROOT / "recordings").glob("*.scenario.json")):
        if p.stat().st_size <= 8192:
            put("scenario", p.name, p.read_bytes())
    # Short enough (under 30 s of hand motion) for the target to synthesize it, and touching
    # every step type, a surface with a dent, a section stroke and a drag.
    put("scenario", "short-every-step.json", json.dumps({
        "format": "lobesketch-scenario", "version": 1, "name": "short", "seed": 3, "rate_hz": 60,
        "surfaces": [{"center": [0, 1.3, -0.4], "radii": [0.12, 0.1, 0.11], "axes": [[1, 0, 0], [0, 1, 0]],
                      "dents": [{"direction": [-1, 0, 0], "depth_mm": 20, "width_deg": 40}]}],
        "steps": [
            {"type": "stroke", "kind": "lobe", "hand": "right",
             "section": {"surface": 0, "normal": [0, 1, 0], "start_angle_deg": 10, "sweep_deg": 120, "wobble_mm": 2}},
            {"type": "near_pinch", "hand": "left", "at": [0.1, 1.2, -0.3], "duration": 0.6},
            {"type": "grab", "hand": "right", "at": [0, 1.2, -0.3], "duration": 0.6},
            {"type": "key", "key": "D"},
            {"type": "drag", "hand": "right", "from": [0.12, 1.3, -0.4], "to": [0.16, 1.3, -0.4]},
            {"type": "pause", "duration": 0.3},
            {"type": "stroke", "kind": "trunk", "hand": "left", "curve": [[0, 0, -0.4], [0, 0.5, -0.4], [0.02, 1.0, -0.4]]}]},
        indent=1))


def repair_seeds():
    """Small meshes for mesh_repair, one per repair step: a closed one, a hole, a
    non-manifold vertex, duplicate and degenerate faces, faces the wrong way round, two
    components, a self-intersection, and the refusals (a flat sheet, collinear corners)."""
    def obj(vs, fs):
        return "".join("v %g %g %g\n" % v for v in vs) + "".join("f %d %d %d\n" % tuple(i + 1 for i in f) for f in fs)
    cube_v = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    cube_f = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
              (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    tet_v = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
    tet_f = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    put("mesh_repair", "cube.obj", obj(cube_v, cube_f))
    put("mesh_repair", "cube-hole.obj", obj(cube_v, cube_f[2:]))
    put("mesh_repair", "cube-inside-out.obj", obj(cube_v, [(a, c, b) for a, b, c in cube_f]))
    put("mesh_repair", "cube-duplicate-degenerate.obj", obj(cube_v, cube_f + [cube_f[0], (0, 0, 1), (1, 0, 3)]))
    two_tets_v = tet_v + [(x, y, z + 1) for x, y, z in tet_v[1:]]  # sharing vertex 3
    two_tets_f = tet_f + [(3, 5, 4), (3, 4, 6), (3, 6, 5), (4, 5, 6)]
    put("mesh_repair", "tets-sharing-a-vertex.obj", obj(two_tets_v, two_tets_f))
    put("mesh_repair", "two-components.obj", obj(tet_v + [(x + 3, y, z) for x, y, z in cube_v],
                                                  tet_f + [(a + 4, b + 4, c + 4) for a, b, c in cube_f]))
    put("mesh_repair", "self-intersecting.obj", obj(cube_v + [(x + 0.5, y + 0.3, z + 0.2) for x, y, z in cube_v],
                                                    cube_f + [(a + 8, b + 8, c + 8) for a, b, c in cube_f]))
    put("mesh_repair", "flat-triangle.obj", obj(tet_v[:3], [(0, 1, 2)]))
    put("mesh_repair", "collinear.obj", obj([(0, 0, 0), (1, 0, 0), (2, 0, 0)], [(0, 1, 2)]))


def lobe_strokes_seeds():
    """Byte strings for lobe_strokes (fuzz/lobe_strokes_fuzz.cpp reads them a byte at a time):
    a stroke count, then per stroke its kind (bit 0 arc, bit 1 reversed, bit 2 shifted, bits
    3-6 a special case: 0 folded back, 1 one point, 2 one line, 3 a stroke again, 4 a NaN,
    5 an enormous coordinate, 6 too few points, others none), tilt, turn, size, height, point
    count, [sweep], wobble, frequency, [shift x y z], [the special case's byte]."""
    plain = 7 << 3  # no special case

    def stroke(kind, tilt, turn, size, height, n, wobble=40, freq=5, sweep=None, shift=None, extra=None):
        b = [kind, tilt, turn, size, height, n]
        if kind & 1:
            b.append(sweep if sweep is not None else 120)
        b += [wobble, freq]
        if kind & 4:
            b += shift or [128, 128, 128]
        if extra is not None:
            b.append(extra)
        return b

    loops = [stroke(plain, t, u, 150, 128, 120) for t, u in [(0, 0), (128, 0), (128, 64), (64, 200)]]
    put("lobe_strokes", "four-loops", bytes([4] + sum(loops, [])))
    rings = [stroke(plain, 0, 0, 150, h, 140) for h in (60, 100, 160, 200)] + [stroke(plain | 2, 128, 32, 150, 128, 140)]
    put("lobe_strokes", "stacked-rings-and-a-loop-drawn-backwards", bytes([5] + sum(rings, [])))
    arcs = loops[:2] + [stroke(plain | 1, 64, 10, 150, 180, 60, sweep=110)]
    put("lobe_strokes", "two-loops-and-an-arc", bytes([3] + sum(arcs, [])))
    odd = loops[:2] + [stroke(3 << 3, 0, 0, 0, 0, 0, extra=1), stroke(plain | 4, 90, 90, 60, 128, 80, shift=[255, 0, 255]),
                       stroke(0 << 3, 30, 30, 150, 128, 50), stroke(4 << 3, 128, 128, 150, 128, 100, extra=7)]
    put("lobe_strokes", "a-loop-again-a-far-one-a-fold-and-a-nan", bytes([6] + sum(odd, [])))
    # Found by the target once it remeshed its lobes (docs/fuzzing.md): a NaN and a fold
    # refused, then a wobbly loop and an arc drawn back over it; a region of the lobe lay on
    # one line of its remeshing chart.
    put("lobe_strokes", "a-loop-and-an-arc-back-over-it-a-region-on-one-chart-line",
        bytes([3, 160, 162, 32, 0, 128, 96, 0, 0, 56, 128, 0, 150, 128, 120, 40, 5, 57, 64] + [251] * 15 +
              [0, 150, 100] + [251] * 6 + [10, 150, 180, 60, 110, 40, 5]))


def hole_fill_seeds():
    """Byte strings for hole_fill (fuzz/hole_fill_fuzz.cpp): shape, two bytes of size, waves
    or bands, amplitude, then one byte per vertex moved beside the hole."""
    def dome(edges, waves, amplitude, moves=b""):
        wide = edges - 201
        return bytes([0, wide & 255, wide >> 8, waves, amplitude]) + moves
    def slit(degrees, bands, moves=b""):
        wide = degrees - 60
        return bytes([1, wide & 255, wide >> 8, bands - 20, 0]) + moves
    put("hole_fill", "dome-300-edges-40-waves", dome(300, 40, 15))
    put("hole_fill", "dome-700-edges-140-waves", dome(700, 140, 20))
    put("hole_fill", "dome-250-edges-flat-base", dome(250, 0, 0))
    put("hole_fill", "dome-400-edges-folding", dome(400, 80, 45))
    put("hole_fill", "dome-300-edges-bumped", dome(300, 20, 10, bytes((i * 37) & 255 for i in range(120))))
    # the target's findings (docs/fuzzing.md): each took over 30 s under ASan
    put("hole_fill", "dome-400-edges-steep-zigzag", dome(400, 80, 37, bytes([0x2d])))
    put("hole_fill", "dome-316-edges-shifted-base", bytes.fromhex(
        "00f33e3e3e" + "00" * 45 + "013c000a0000356a9fd4093e73a8dd12477cb1e61b5085baef24598ec3f82d6297cc01366ba0d50a3f74a9de"
        "13487db2e71c5186bbf0255a8fc4f9dd12477cb1e61b5085baef24598ec3f82d6297cc01366ba0d50a3f74a9de133e3e7eb33e"))
    # a 638-edge base swinging ±37° in 241 waves and shifted 4 cm through the dome's first
    # band: over 30 s under ASan in CGAL's removal, which the project's own cut replaced
    put("hole_fill", "dome-638-edges-folded-and-shifted", bytes.fromhex("00" + "f1" * 73 + "31750000"))
    # a 700-edge base of 93 waves of ±38°, vertices moved: the first cut's patch repeated an
    # edge of the surface, which the removal's first form kept (refused as not 2-manifold)
    put("hole_fill", "dome-700-edges-93-waves-moved", bytes.fromhex(
        "00f3015d8c1400f33e3e3e3e3e3e3e3e3e3e3e3e3e3e3e00f33e3e3e3e3e8c14"))
    put("hole_fill", "slit-300-degrees", slit(300, 40))
    put("hole_fill", "slit-120-degrees-bumped", slit(120, 30, bytes((i * 53) & 255 for i in range(200))))
    # a 247° slit through 20 bands, 43 vertices moved (random bytes): its border runs over
    # itself in its plane and gets the searched patch, which CGAL's search chose among equal
    # ones by memory order (docs/lobes-from-models.md, Limits)
    put("hole_fill", "slit-247-degrees-searched", bytes.fromhex(
        "b31e74c0d1c0720f800a86de7b76b568a6d98e98ff6e50f4"
        "884599902da902f87f52a3e76c1a6bb817e05dde47980c39"))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--lobesketch", help="a built lobesketch, to remake the text-recording and session seeds")
    a = ap.parse_args()
    for t in ["import_leap", "import_webxr", "recording_binary", "mesh_obj", "mesh_ply", "mesh_off", "mesh_repair",
              "hole_fill", "lobe_strokes", "species", "desktop_script", "scenario"]:
        shutil.rmtree(OUT / t, ignore_errors=True)
    leap_seeds()
    webxr_seeds()
    recording_binary_seeds()
    mesh_seeds()
    repair_seeds()
    hole_fill_seeds()
    lobe_strokes_seeds()
    species_seeds()
    desktop_script_seeds()
    scenario_seeds()
    text_recording_seeds(a.lobesketch)
    session_seeds(a.lobesketch)
    for d in sorted(OUT.iterdir()):
        files = list(d.iterdir())
        print(f"{d.name}: {len(files)} seeds, {sum(f.stat().st_size for f in files)} bytes")


if __name__ == "__main__":
    main()
