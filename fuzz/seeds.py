#!/usr/bin/env python3
"""Writes the committed seed corpus: the shared models cut into pieces.

    python3 fuzz/seeds.py            # rewrites fuzz/seeds/<target>/

Each seed is a fuzz input in the layout of `fuzz/src/big.rs`: a mesh blob
(frame size, flags, camera, positions as i16 / 8192, index triples) holding
one piece of `assets/models/*.obj` (a run of consecutive faces, re-indexed:
a few hundred to a few thousand triangles), then a short random tail that
`arbitrary` turns into the rest of `FrameInput` (extra submissions, row
window, splits, pixel and depth formats, bins, wrong calls, StripDrawer).
Deterministic (fixed random seed); the same pieces go to both targets,
with different tails. Keep the total under ~2 MB (it prints the sizes).

The `shading` target's seeds (fuzz/seeds/shading/, layout in
`fuzz/src/shading.rs`) are pieces of spot (the one model with texture
coordinates) with normals (face normals averaged per vertex, some pieces
with a few zero or rescaled) and uvs (OBJ's v flipped), a few dozen under
~200 KB, from their own random stream (the other targets' seeds do not
change).
"""

import os
import random
import struct
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODELS = ["spot", "teapot", "stanford-bunny"]
TARGETS = ["frame", "strip_renderer"]
# (model, faces per piece, pieces)
PLAN = [
    ("spot", 200, 3),
    ("spot", 800, 3),
    ("spot", 2000, 2),
    ("teapot", 300, 3),
    ("teapot", 1000, 3),
    ("teapot", 2400, 1),
    ("stanford-bunny", 250, 3),
    ("stanford-bunny", 1200, 3),
    ("stanford-bunny", 1600, 2),
]
SIZES = [(97, 61), (160, 120), (64, 64), (33, 250), (250, 33), (1, 50),
         (128, 1), (255, 255), (320, 200), (17, 13)]
MAX_LEN = 32768


def load_obj(path):
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append(tuple(float(x) for x in p[1:4]))
            elif p[0] == "f":
                idx = [int(t.split("/")[0]) for t in p[1:]]
                idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
                for k in range(1, len(idx) - 1):
                    faces.append((idx[0], idx[k], idx[k + 1]))
    # Centre on the bounding box, scale to radius 1.
    lo = [min(v[k] for v in verts) for k in range(3)]
    hi = [max(v[k] for v in verts) for k in range(3)]
    c = [(lo[k] + hi[k]) / 2 for k in range(3)]
    r = max(sum((v[k] - c[k]) ** 2 for k in range(3)) ** 0.5 for v in verts)
    verts = [tuple((v[k] - c[k]) / r for k in range(3)) for v in verts]
    return verts, faces


def piece(verts, faces, start, n):
    fs = faces[start:start + n]
    remap, pos = {}, []
    tris = []
    for f in fs:
        t = []
        for i in f:
            if i not in remap:
                remap[i] = len(pos)
                pos.append(verts[i])
            t.append(remap[i])
        tris.append(t)
    return pos, tris


def blob(rng, pos, tris):
    w, h = rng.choice(SIZES)
    backend = rng.randrange(3)
    bounds = rng.random() < 0.6
    color_mode = rng.randrange(3)
    path = rng.randrange(4)
    tight = rng.random() < 0.5
    flags = backend | (bounds << 2) | (color_mode << 3) | (path << 5) | (tight << 7)
    # Camera: around the model, sometimes inside its near plane or far
    # enough that the piece is small, sometimes looking away (culled).
    d = rng.choice([2.2, 3.0, 4.0, 8.0, 1.2])
    dx, dy, dz = (rng.uniform(-1, 1) for _ in range(3))
    n = max((dx * dx + dy * dy + dz * dz) ** 0.5, 1e-3)
    eye = (dx / n * d, dy / n * d, dz / n * d)
    target = (0.0, 0.0, 0.0)
    if rng.random() < 0.15:
        target = (eye[0] * 2, eye[1] * 2, eye[2] * 2)  # looking away
    fov = rng.choice([0.6, 0.9, 1.2, 2.5])
    near = rng.choice([0.1, 0.5, d - 0.3])
    far = rng.choice([10.0, 100.0, d + 0.2])
    angle = rng.uniform(-3.2, 3.2)
    out = struct.pack("<HHBB", w, h, flags, rng.randrange(256))
    out += struct.pack("<10f", *eye, *target, fov, near, far, angle)
    out += struct.pack("<H", len(pos))
    for p in pos:
        out += struct.pack("<3h", *(max(-32768, min(32767, round(c * 8192))) for c in p))
    for t in tris:
        out += struct.pack("<3H", *t)
    return out


def main():
    rng = random.Random(20261201)
    models = {m: load_obj(os.path.join(ROOT, "assets", "models", m + ".obj")) for m in MODELS}
    total = 0
    for t in TARGETS:
        d = os.path.join(ROOT, "fuzz", "seeds", t)
        os.makedirs(d, exist_ok=True)
        for f in os.listdir(d):
            os.remove(os.path.join(d, f))
    k = 0
    for model, n, count in PLAN:
        verts, faces = models[model]
        for _ in range(count):
            start = rng.randrange(0, max(1, len(faces) - n))
            pos, tris = piece(verts, faces, start, n)
            for t in TARGETS:
                b = blob(rng, pos, tris)
                tail = bytes(rng.randrange(256) for _ in range(rng.randrange(24, 160)))
                data = struct.pack("<I", len(b)) + b + tail
                assert len(data) <= MAX_LEN, (model, n, len(data))
                name = f"{model}-{n}-{start}"
                with open(os.path.join(ROOT, "fuzz", "seeds", t, name), "wb") as f:
                    f.write(data)
                total += len(data)
                k += 1
    print(f"{k} seeds, {total} bytes", file=sys.stderr)
    shading_seeds()


def load_obj_uv(path):
    """Positions (centred, radius 1), uvs, and triangles of (v, vt) pairs."""
    verts, uvs, faces = [], [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append(tuple(float(x) for x in p[1:4]))
            elif p[0] == "vt":
                uvs.append((float(p[1]), 1.0 - float(p[2])))
            elif p[0] == "f":
                c = []
                for t in p[1:]:
                    a = t.split("/")
                    c.append((int(a[0]) - 1, int(a[1]) - 1 if len(a) > 1 and a[1] else 0))
                for k in range(1, len(c) - 1):
                    faces.append((c[0], c[k], c[k + 1]))
    lo = [min(v[k] for v in verts) for k in range(3)]
    hi = [max(v[k] for v in verts) for k in range(3)]
    cen = [(lo[k] + hi[k]) / 2 for k in range(3)]
    r = max(sum((v[k] - cen[k]) ** 2 for k in range(3)) ** 0.5 for v in verts)
    verts = [tuple((v[k] - cen[k]) / r for k in range(3)) for v in verts]
    # Smooth normals: face normals (area-weighted) summed per position.
    acc = [[0.0, 0.0, 0.0] for _ in verts]
    for f in faces:
        a, b, c = (verts[i] for i, _ in f)
        u = [b[k] - a[k] for k in range(3)]
        v = [c[k] - a[k] for k in range(3)]
        n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
        for i, _ in f:
            for k in range(3):
                acc[i][k] += n[k]
    normals = []
    for n in acc:
        l = max(sum(x * x for x in n) ** 0.5, 1e-12)
        normals.append(tuple(x / l for x in n))
    return verts, normals, uvs, faces


def q(x, scale):
    return max(-32768, min(32767, round(x * scale)))


def shading_seeds():
    rng = random.Random(20261202)
    verts, normals, uvs, faces = load_obj_uv(os.path.join(ROOT, "assets", "models", "spot.obj"))
    d = os.path.join(ROOT, "fuzz", "seeds", "shading")
    os.makedirs(d, exist_ok=True)
    for f in os.listdir(d):
        os.remove(os.path.join(d, f))
    sizes = [(64, 48), (97, 61), (128, 96), (33, 120), (120, 33), (17, 13), (160, 100)]
    total = count = 0
    for n in [40, 80, 150, 250, 400] * 8:
        start = rng.randrange(0, len(faces) - n)
        remap, vs, tris = {}, [], []
        for f in faces[start:start + n]:
            t = []
            for pair in f:
                if pair not in remap:
                    remap[pair] = len(vs)
                    vs.append(pair)
                t.append(remap[pair])
            tris.append(t)
        w, h = rng.choice(sizes)
        # Most seeds: full lists, rows from the top, stock texture and
        # lights where the tail's are refused (see fuzz/src/shading.rs).
        flags = rng.randrange(3) | ((rng.random() < 0.5) << 2) | (rng.randrange(3) << 3)
        flags |= (rng.random() < 0.8) << 5
        flags |= (rng.random() < 0.8) << 6
        flags |= (rng.random() < 0.85) << 7
        dist = rng.choice([2.2, 3.0, 4.0, 1.5])
        dx, dy, dz = (rng.uniform(-1, 1) for _ in range(3))
        l = max((dx * dx + dy * dy + dz * dz) ** 0.5, 1e-3)
        eye = (dx / l * dist, dy / l * dist, dz / l * dist)
        fov = rng.choice([0.6, 0.9, 1.2])
        out = struct.pack("<HHB", w, h, flags)
        out += struct.pack("<10f", *eye, 0.0, 0.0, 0.0, fov, 0.1, 20.0, rng.uniform(-3.2, 3.2))
        out += struct.pack("<H", len(vs))
        odd = rng.random() < 0.3
        for vi, ti in vs:
            p, nm, uv = verts[vi], normals[vi], uvs[ti]
            s = 8192
            if odd:
                s = rng.choice([0, 8192, 4096, 16000])  # zero or not unit
            out += struct.pack("<3h", *(q(c, 8192) for c in p))
            out += struct.pack("<3h", *(q(c, s) for c in nm))
            out += struct.pack("<2h", *(q(c, 4096) for c in uv))
        for t in tris:
            out += struct.pack("<3H", *t)
        tail = bytes(rng.randrange(256) for _ in range(rng.randrange(60, 200)))
        data = struct.pack("<I", len(out)) + out + tail
        with open(os.path.join(d, f"spot-{n}-{start}"), "wb") as f:
            f.write(data)
        total += len(data)
        count += 1
    print(f"shading: {count} seeds, {total} bytes", file=sys.stderr)


if __name__ == "__main__":
    main()
