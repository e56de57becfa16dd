#!/usr/bin/env python3
"""Writes hand-made seed inputs for fuzz_select, fuzz_schedule and fuzz_stream
that reach what random bytes find slowly: additive and empty nodes, boxes
valid and bad, the overflow policy, and edits between frames (removals with
subtrees, removals twice, moves, adds under removed parents, hidden ids,
smooth edits), edits tried while a resumable solve is pending and from inside
callbacks, and ids given again after every selector solved; residency flipped
around drawn nodes, sizes and stream descs good and bad.

    tests/fuzz/make_seeds.py [CORPUS_DIR]   (default: tests/fuzz/corpus)

with the reproducers of the library bugs fuzzing found (README.md, F1-F6).

Files are named by the SHA-1 of their bytes, as libFuzzer names them, so
running it again adds nothing new. The byte layout is the one fuzz_host.c
and the targets read (their readers are the reference); a change there
changes what these bytes mean, but any bytes stay a valid input.
"""
import hashlib
import json
import os
import struct
import sys

# ---- values ----------------------------------------------------------------

def dbl(x):
    """fuzz_double's byte for x: 1 + k/16 times a power of two, or 0."""
    if x == 0:
        return [0]
    specials = {1e300: 11, -1.0: 16, float("nan"): 15, float("inf"): 13}
    if x in specials:
        return [specials[x]]
    for b in range(32, 248):
        if (1 + (b & 15) / 16) * 2.0 ** ((b >> 4) - 7) == x:
            return [b]
    raise ValueError(x)


def flt(x):
    """fuzz_float's byte for x: a multiple of 7/8 in [-98, 111], or special."""
    specials = {"nan": 8, "inf": 6, "max": 4, "1e30": 9}
    if isinstance(x, str):
        return [specials[x]]
    b = round(x / 0.875) + 128
    assert 16 <= b <= 255 and (b - 128) * 0.875 == x, x
    return [b]


def sphere(x, y, z, r, negative=False):
    """read_bounds: three coordinates, a radius, and its sign byte."""
    return flt(x) + flt(y) + flt(z) + flt(r) + [0x80 if negative else 0]


def shape(kind, centre, sizes, rotation=(0,), skew=0, spoil=None):
    """read_shape for kind 1 (sphere, sizes = [r]), 2 (AABB) or 3 (OBB):
    the centre, the rotation bytes (OBB), the lengths, the skew byte (OBB),
    the spoil byte and its field byte."""
    out = []
    for c in centre:
        out += flt(c)
    if kind == 3:
        out += list(rotation)
    for s in sizes:
        out += flt(s)
    if kind == 3:
        out += [skew]
    out += list(spoil) if spoil else [0]
    return out


# ---- structure ---------------------------------------------------------------

REPLACE, ADD, EMPTY = 0, 2, 3


def node(parent, kind=REPLACE, bounds=None, b=1.0, c=1.0, cx=1.0, alt=0):
    """read_node_spec. parent: a byte (k-th live node, 0xff a root, 0xe0 + k
    any id k). bounds: None, ("sphere", [...bytes]) or (shape 1-3, bytes)."""
    k = kind << 3 | alt << 5
    tail = []
    if bounds is not None:
        what, data = bounds
        k |= 1 | (0 if what == "sphere" else what << 1)
        tail = data
    return [parent, k] + tail + dbl(b) + dbl(c) + dbl(cx)


def smooth(x, z, r, w=1.0, k=1.0, mode=0x01):
    """read_smooth_spec: bounds, mode, w, k, no dishonest slope, complexity."""
    return sphere(x, 0, z, r) + [mode] + dbl(w) + dbl(k) + [0] + dbl(1.0)


def desc(solver=0, flags=0x01, enums=0, overflow=0):
    """read_desc: solver, flags, enums, five options (defaults), overflow."""
    return [solver, flags, enums, 0, 0, 0, 0, 0, overflow]


# read_edit ops (op % 8) and their arguments
def remove(idb):
    return [0, idb]


def remove_smooth(idb):
    return [1, idb]


def move(idb, bounds_bytes):
    """bounds_bytes: read_node_bounds's shape byte (0 none, 1 float sphere,
    2 double sphere, 3 AABB, 4 OBB) and what follows it."""
    return [2, idb] + bounds_bytes


def move_null(idb):
    return [2 | 0x1f << 3, idb]


def move_smooth(idb, x, z, r, negative=False):
    return [3, idb] + sphere(x, 0, z, r, negative)


def add(spec):
    return [4] + spec


def add_smooth(spec):
    return [5] + spec


def remove_twice(idb):
    return [6, idb]


def hidden(sub, kbyte, extra=()):
    """an additive node's hidden id (the kbyte-th known one): sub 0 remove,
    1 move (extra: node bounds), 2 add a child (extra: a node spec)."""
    return [7 | sub << 3, kbyte] + list(extra)


def view_path(t=0):
    return [64 + t]


# ---- fuzz_select ---------------------------------------------------------------

def frame(edits=(), adds=(), callback_edit=None, pending_edit=None, view=None, budget=160,
          limit=0, seconds=0, how=0, values=()):
    """One frame: value changes, adds (node spec, smooth spec or None),
    edits, the held edits, view, budget byte (>= 32: a share of the summed
    costs, (b - 32) / 128), limit, solve_seconds and how bytes."""
    out = [len(values)]
    for idb, which, v in values:
        out += [idb, which] + dbl(v)
    assert len(adds) < 4 and len(edits) < 4
    g = len(adds) | len(edits) << 2
    g |= 0x40 if callback_edit else 0
    g |= 0x80 if pending_edit else 0
    out.append(g)
    for n, sm in adds:
        out += n + ([1] + sm if sm else [0])
    for e in edits:
        out += e
    if callback_edit:
        out += callback_edit
    if pending_edit:
        out += pending_edit
    out += view if view is not None else [0]
    out += [budget, limit, seconds, how]
    return out


def select_input(d, nodes, smooths, frames, prepare=1):
    out = list(d) + [len(nodes)]
    for n in nodes:
        out += n
    out.append(len(smooths))
    for sm in smooths:
        out += sm
    out += [prepare, len(frames) - 1]
    for f in frames:
        out += f
    return bytes(out)


def hierarchy():
    """An additive root with an AABB (ids 0, hidden 1), an empty child (2)
    with an OBB grandchild (3) and a sphere one (4), a replace child (5) with
    two children (6, 7), and a replace root (8) with an additive child (9,
    hidden 10)."""
    aabb = (2, shape(2, [0, 0, 21], [7, 7, 7]))
    obb = (3, shape(3, [0, 0, 21], [3.5, 1.75, 0.875], rotation=(1 | 1 << 2, 32)))
    return [
        node(0xff, ADD, aabb, b=4.0, c=1.0),
        node(0, EMPTY),
        node(1, REPLACE, obb, b=2.0, c=1.0),
        node(1, REPLACE, ("sphere", sphere(3.5, 0, 21, 1.75)), b=2.0, c=1.0),
        node(0, REPLACE, ("sphere", sphere(-3.5, 0, 21, 3.5)), b=3.0, c=1.0),
        node(4, REPLACE, None, b=2.0, c=0.5),
        node(4, REPLACE, None, b=2.0, c=0.5),
        node(0xff, REPLACE, (1, shape(1, [21, 0, 21], [7])), b=2.0, c=2.0),
        node(7, ADD, (2, shape(2, [21, 0, 21], [3.5, 3.5, 3.5])), b=3.0, c=1.0),
    ]


def select_seeds():
    seeds = []
    nodes = hierarchy()
    smooths = [smooth(0, 10.5, 1.75), smooth(7, 10.5, 1.75), smooth(-7, 14, 0.875)]
    skewed = [4] + shape(3, [0, 0, 21], [3.5, 3.5, 3.5], skew=0xf3)  # |cos| 2e-3: bad
    leaning = [4] + shape(3, [0, 0, 21], [3.5, 3.5, 3.5], skew=0xf0)  # 5e-4: a box
    nan_box = [3] + shape(2, [0, 0, 21], [1.75, 1.75, 1.75], spoil=(0x81, 1))
    negative_box = [3] + shape(2, [0, 0, 21], [1.75, 1.75, 1.75], spoil=(0x80, 2))
    for solver in (0, 1, 2):
        # edits between frames, the held edits, resumable and plain selects
        frames = [
            frame(view=view_path(10), budget=96),
            frame(edits=[remove(3), move(2, skewed), remove_twice(4)],
                  callback_edit=remove(0), pending_edit=move(0, leaning),
                  view=view_path(20), budget=120, how=64 + 2 * 4),
            frame(edits=[hidden(0, 0), add(node(0xe0 + 5, REPLACE, None)), move(1, nan_box)],
                  adds=[(node(0, ADD, None, b=2.0, c=0.5), smooth(3.5, 10.5, 0.875))],
                  view=view_path(30), budget=200, how=64 + 1 + 4),
            frame(edits=[remove_smooth(1), move_smooth(0, 14, 14, 1.75),
                         move(0, negative_box)],
                  callback_edit=add(node(0xff, REPLACE, None)),
                  pending_edit=remove_smooth(0), view=view_path(40), budget=160, how=64 + 4),
        ]
        seeds.append(select_input(desc(solver=solver, flags=0x01), nodes, smooths, frames))
        # the roots over the budget: drawn (overflow 1) or dropped
        for overflow in (0, 1):
            frames = [frame(view=view_path(5), budget=0),
                      frame(edits=[remove(0)], view=view_path(6), budget=33),
                      frame(edits=[hidden(1, 0, [0]), move_null(1)], budget=2)]
            seeds.append(select_input(desc(solver=solver, flags=0x01, overflow=overflow),
                                      nodes, smooths, frames))
    # ids given again: remove, solve (both selectors), add, solve, add again
    frames = [frame(budget=160),
              frame(edits=[remove(0), remove(5)], budget=160),
              frame(adds=[(node(0xff, ADD, None, b=2.0), None),
                          (node(0xff, REPLACE, None, b=2.0), None),
                          (node(0, REPLACE, None, b=1.0), None)],
                    edits=[add(node(0xff, ADD, None)), add(node(0xe0 + 1, REPLACE, None))],
                    budget=160),
              frame(edits=[remove(0), add(node(0xff, REPLACE, None)),
                           add(node(0xff, ADD, None))], budget=160, how=64 + 3),
              frame(edits=[remove_smooth(0), add_smooth(smooth(3.5, 7, 0.875))], budget=160),
              frame(edits=[add_smooth(smooth(-3.5, 7, 0.875)), remove_smooth(0xc0 + 1)],
                    budget=160)]
    seeds.append(select_input(desc(solver=1, flags=0x01), nodes,
                              [smooth(0, 10.5, 1.75), smooth(7, 10.5, 1.75)], frames))
    # F4: a warm start after an additive root's benefit fell to 0
    frames = [frame(budget=255),
              frame(values=[(0, 0, 0.0)], budget=255)]
    seeds.append(select_input(desc(solver=0, flags=0x01),
                              [node(0xff, ADD, None, b=1.0, c=1.0),
                               node(0, REPLACE, None, b=2.0, c=1.0)], [], frames))
    # F2: drawn over the budget, then a free increment
    seeds.append(select_input(desc(solver=0, flags=0x00, overflow=1),
                              [node(0xff, REPLACE, None, b=0.75, c=1.0),
                               node(0, REPLACE, None, b=1.0, c=0.0)], [],
                              [frame(budget=0)]))
    # F3: a smooth object whose radius is float's largest
    big = sphere(0, 0, 10.5, "max") + [0x01] + dbl(1.0) + dbl(1.0) + [0] + dbl(1.0)
    seeds.append(select_input(desc(solver=1, flags=0x01), [node(0xff, REPLACE, None)],
                              [big],
                              [frame(view=view_path(10), budget=160)]))
    # F1: Robin Hood over a scene without children
    seeds.append(select_input(desc(solver=2, flags=0x00), [node(0xff, REPLACE, None)], [],
                              [frame(budget=0x60)]))
    # F6: a greedy warm start after nodes were added and one of them removed
    # (the root joined the cut twice)
    frames = [frame(budget=0),
              frame(adds=[(node(0xff, REPLACE, None, b=1.0, c=1.0), None),
                          (node(0, REPLACE, None, b=1.0, c=1.0), None),
                          (node(1, REPLACE, None, b=1.0, c=1.0), None)],
                    edits=[remove(2)], budget=255)]
    seeds.append(select_input(desc(solver=0, flags=0x01), [], [], frames))
    return seeds


# ---- fuzz_schedule -------------------------------------------------------------

def schedule_input(d, nodes, smooths, updates):
    """read_desc, read_schedule_desc (defaults: tau 0.5, samples 3, speed 20,
    turn 1, morph on), the scene, the start time, the updates."""
    out = list(d) + [0, 0, 0, 0, 0, 0, 0] + [len(nodes)]
    for n in nodes:
        out += n
    out.append(len(smooths))
    for sm in smooths:
        out += sm
    out += [0, 0, len(updates) - 1]
    for u in updates:
        out += u
    return bytes(out)


def update(step=2, edits=(), callback_edit=None, grow=None, view=None, budget=160):
    """One update: the time step (steps[] index), the scene byte (0x77 with
    grow: add a node; 0xe0 + edits - 1 (+4 with a callback edit) or 0xd0
    with only a callback edit), the view, budget, slice 0, no report."""
    out = [step]
    if grow is not None:
        out += [0x77] + grow
    elif edits:
        assert 1 <= len(edits) <= 4
        out += [0xe0 + len(edits) - 1 + (4 if callback_edit else 0)]
        for e in edits:
            out += e
        if callback_edit:
            out += callback_edit
    elif callback_edit:
        out += [0xd0] + callback_edit
    else:
        out += [0]
    out += view if view is not None else view_path(0)
    out += [budget, 0, 0]
    return out


def schedule_seeds():
    seeds = []
    nodes = hierarchy()
    smooths = [smooth(0, 10.5, 1.75), smooth(7, 10.5, 1.75)]
    for solver in (0, 1, 2):
        updates = []
        for u in range(10):
            edits, cb = (), None
            if u == 3:
                edits = [remove(3), move(0, [4] + shape(3, [0, 0, 21], [7, 3.5, 3.5]))]
            if u == 5:
                edits, cb = [remove(0), add(node(0xe0 + 2, REPLACE, None))], remove(1)
            if u == 7:
                edits = [add(node(0xff, ADD, None)), remove_smooth(0), hidden(2, 0, node(0xff))]
            if u == 8:
                cb = move_smooth(0, 0, 7, 1.75)
            updates.append(update(step=2 + u % 3, edits=edits, callback_edit=cb,
                                  view=view_path(8 * u), budget=120))
        seeds.append(schedule_input(desc(solver=solver, flags=0x01), nodes, smooths, updates))
        # the roots over the budget
        updates = [update(view=view_path(4 * u), budget=33 if u < 4 else 0) for u in range(8)]
        seeds.append(schedule_input(desc(solver=solver, flags=0x01, overflow=1), nodes,
                                    smooths, updates))
    # the mixed solver without smooth callbacks, until a smooth object is added
    updates = [update(budget=120), update(edits=[add_smooth(smooth(0, 10.5, 1.75))]),
               update(edits=[remove_smooth(0)]), update(budget=120)]
    seeds.append(schedule_input(desc(solver=1, flags=0x11), nodes, [], updates))
    return seeds


# ---- fuzz_stream ---------------------------------------------------------------

# residency calls: set_resident, set_smooth_resident, set_node_bytes,
# set_smooth_bytes; flags by read_flag's index: 0 -> 0, 1 -> 1, 6 -> 2, 7 -> -1
RESIDENT, SMOOTH_RESIDENT, BYTES, SMOOTH_BYTES = 0, 1, 2, 3
UNLOAD, LOAD, FLAG_TWO = 0, 1, 6


def residency(op, idb, flag=UNLOAD, size=None):
    """operate 0: a residency call (size: read_bytes's byte, for the sizes)."""
    return [0, op + 4 * flag, idb] + ([size] if op >= BYTES else [])


def grow_one(spec, smooth_spec=None, settle=(0,)):
    """operate 3: a node (and a smooth object), each then settled by a byte:
    bit 0 unloads it, bits 2-7 size it (x 1024, smooth x 512) with bit 1."""
    return [3, 1 if smooth_spec else 0] + spec + (smooth_spec or []) + list(settle)


def stream_edit(e, settle=()):
    """operate 4: a fuzz_host edit, and a settling byte per new id."""
    return [4] + e + list(settle)


def stream_desc(requests, request_bytes=0, budget=0, flight=0):
    """operate 5: max_requests byte, then three size bytes (< 32: a special
    double; else (b & 15) * 8^(b >> 4))."""
    return [5, requests, request_bytes, budget, flight]


def bytes_answer(slot, x):
    """operate 6: what the bytes callback says of node slot (smooth: 384 +)."""
    return [6, slot] + ([15] if x != x else dbl(x))


def stream_frame(ops=(), held=None, view=None, budget=255, limit=0, how=0):
    """One frame: the operations, the held call (op, id byte, flag index,
    size byte), view, budget, limit and how bytes."""
    out = [len(ops)]
    for o in ops:
        out += o
    if held:
        op, idb, flag = held[:3]
        out += [1, op, idb, flag] + ([held[3]] if op >= BYTES else [])
    else:
        out += [0]
    out += view if view is not None else [0]
    out += [budget, limit, how]
    return out


def stream_input(d, nodes, smooths, settle, frames, bytes_callback=True):
    out = list(d) + [1 if bytes_callback else 0, len(nodes), len(smooths)]
    for n in nodes:
        out += n
    for sm in smooths:
        out += sm
    out += list(settle)
    out.append(len(frames) - 1)
    for f in frames:
        out += f
    return bytes(out)


def stream_seeds():
    """Two hierarchies R -> {A -> {A1, A2}, B} (ids 0-4) and Q -> {Q1, Q2}
    (5-7), all resident, and three smooth objects: everything drawn; then A
    unloaded (a warm cut keeps A1, A2 below it), A1 too (it falls back to
    R), Q (a root: its hierarchy draws nothing), an additive node whose
    children arrive one by one, sizes good and bad, stream descs good and
    bad, residency tried from a callback and while a solve is pending."""
    seeds = []
    nodes = [node(0xff, b=1.0, c=1.0), node(0, b=2.0, c=1.0), node(1, b=3.0, c=1.0),
             node(1, b=3.0, c=1.0), node(0, b=2.0, c=1.0), node(0xff, b=1.0, c=1.0),
             node(5, b=2.0, c=1.0), node(5, b=2.0, c=1.0)]
    smooths = [smooth(0, 10.5, 1.75), smooth(7, 10.5, 1.75), smooth(-7, 14, 0.875)]
    settle = [2 | 4 << 2] * 8 + [0, 1, 2 | 8 << 2]  # sized; smooth 1 unloaded
    additive = node(0xff, ADD, None, b=2.0, c=1.0)  # id 8, hidden 9
    frames = [
        stream_frame(),
        stream_frame(ops=[residency(RESIDENT, 1)], held=(RESIDENT, 0, UNLOAD)),
        stream_frame(ops=[residency(RESIDENT, 2), residency(BYTES, 3, size=13),
                          residency(BYTES, 4, size=33), stream_desc(4, 0x25, 0x37, 0)],
                     held=(BYTES, 1, 0, 40), how=64 + 2 * 4),
        stream_frame(ops=[residency(RESIDENT, 5), residency(RESIDENT, 1, LOAD),
                          residency(SMOOTH_RESIDENT, 0), residency(RESIDENT, 3, FLAG_TWO),
                          grow_one(additive, settle=(0,)),
                          grow_one(node(8, b=3.0, c=1.0), settle=(1,)),
                          grow_one(node(8, b=3.0, c=1.0), settle=(1,)),
                          stream_desc(2, 15, 0, 0)],
                     held=(SMOOTH_RESIDENT, 2, UNLOAD), how=64 + 1 + 4),
        stream_frame(ops=[residency(RESIDENT, 10, LOAD), residency(RESIDENT, 2, LOAD),
                          bytes_answer(11, float("nan")), stream_edit(remove(1)),
                          residency(SMOOTH_BYTES, 2, size=15)], budget=120),
        stream_frame(ops=[residency(RESIDENT, 11, LOAD), residency(RESIDENT, 5, LOAD),
                          residency(RESIDENT, 0)], view=view_path(10), budget=200,
                     how=64 + 3),
    ]
    # greedy warm (flags bit 0), with a lookahead of 2 (bit 7, enums 1 << 6),
    # the mixed solver with split variables (bit 1), Robin Hood (strict: the
    # NaN size fails its select, bit 2)
    for solver, flags, enums in ((0, 0x01, 0), (0, 0x81, 1 << 6), (1, 0x03, 0), (2, 0x05, 0)):
        seeds.append(stream_input(desc(solver=solver, flags=flags, enums=enums), nodes, smooths,
                                  settle, frames))
    # the same with nodes added not resident from the start, and a root
    # whose benefit is 0 (not counted)
    nodes2 = nodes + [node(0xff, b=0.0, c=1.0)]
    settle2 = [1, 1 | 2 | 4 << 2] + [2 | 4 << 2] * 6 + [1, 0, 0, 0]
    for solver in (0, 1, 2):
        seeds.append(stream_input(desc(solver=solver, flags=0x01), nodes2, smooths, settle2,
                                  frames[:3], bytes_callback=False))
    return seeds


# ---- fuzz_tileset (tests/tiles/fuzz_tileset.c) -------------------------------------

# The names a record's first byte chooses, as FILE_NAMES in fuzz_tileset.c.
TILESET_FILES = ["s000.subtree", "s110.subtree", "s101.subtree", "s232.subtree", "b.bin",
                 "e.json"]


def tileset_record(name, data):
    """A file beside tileset.json: its name's index, a 16-bit length, the bytes."""
    if isinstance(data, str):
        data = data.encode()
    return bytes([TILESET_FILES.index(name)]) + struct.pack("<H", len(data)) + data


def binary_subtree(j, chunk):
    """A binary subtree file: the header, the JSON padded to 8 bytes, the chunk."""
    text = json.dumps(j, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 8)
    return b"subt" + struct.pack("<IQQ", 1, len(text), len(chunk)) + text + chunk


def tileset_json(root, version="1.1"):
    return json.dumps({"asset": {"version": version}, "root": root},
                      separators=(",", ":")).encode()


def tileset_seeds():
    """Every volume kind, a transform and an external tileset; implicit
    quadtrees of boxes (binary subtree, JSON child subtree with an external
    buffer) and of regions across the antimeridian (child subtrees); an
    implicit octree with constant availability; and every deviation the
    reader forgives (docs/tiles.md): errors inherited, refine in lowercase and
    unknown, url for uri, an empty uri, an asset without version, a content
    volume, a child reaching out of its parent, a viewerRequestVolume."""
    implicit = {"subdivisionScheme": "QUADTREE", "subtreeLevels": 2, "availableLevels": 3,
                "subtrees": {"uri": "s{level}{x}{y}.subtree"}}
    listed = tileset_json({
        "geometricError": 100, "refine": "ADD",
        "boundingVolume": {"region": [0.1, 0.7, 0.11, 0.71, 0, 50]}, "content": {"uri": "a.glb"},
        "children": [
            {"geometricError": 10, "boundingVolume": {"box": [0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 2]},
             "transform": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 10, 20, 30, 1],
             "contents": [{"uri": "b.glb"}, {"uri": "c.glb"}],
             "children": [{"geometricError": 0, "boundingVolume": {"sphere": [0, 0, 0, 5]},
                           "content": {"uri": "d.glb"}}]},
            {"geometricError": 5, "boundingVolume": {"sphere": [1, 2, 3, 4]},
             "content": {"uri": "e.json"}}]})
    external = tileset_json({
        "geometricError": 4, "refine": "REPLACE", "boundingVolume": {"sphere": [0, 0, 3, 4]},
        "content": {"url": "f.pnts"},
        "children": [{"geometricError": 0,
                      "boundingVolume": {"box": [0, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1]}}]}, "1.0")
    boxes = tileset_json({
        "geometricError": 64, "refine": "ADD",
        "boundingVolume": {"box": [0, 0, 0, 8, 0, 0, 0, 8, 0, 0, 0, 2]},
        "transform": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 100, 0, 0, 1],
        "content": {"uri": "c/{level}/{x}/{y}.glb"}, "implicitTiling": implicit})
    chunk = bytes([0x13]) + bytes(7) + bytes([0x12]) + bytes(7) + bytes([0x20, 0x20]) + bytes(6)
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 1},
             {"buffer": 0, "byteOffset": 8, "byteLength": 1},
             {"buffer": 0, "byteOffset": 16, "byteLength": 2}]
    root_subtree = binary_subtree({
        "buffers": [{"byteLength": 18}], "bufferViews": views,
        "tileAvailability": {"bitstream": 0}, "contentAvailability": [{"bitstream": 1}],
        "childSubtreeAvailability": {"bitstream": 2}}, chunk)
    child_subtree = json.dumps({
        "buffers": [{"uri": "b.bin", "byteLength": 1}],
        "bufferViews": [{"buffer": 0, "byteLength": 1}], "tileAvailability": {"constant": 1},
        "contentAvailability": [{"bitstream": 0}], "childSubtreeAvailability": {"constant": 1}})
    regions = tileset_json({
        "geometricError": 10,
        "boundingVolume": {"region": [3.0, -0.1, -3.0, 0.1, 0, 100]},
        "contents": [{"uri": "r/{level}_{x}_{y}.glb"}],
        "implicitTiling": dict(implicit, subtreeLevels=1)})
    everything = {"tileAvailability": {"constant": 1}, "contentAvailability": [{"constant": 1}],
                  "childSubtreeAvailability": {"constant": 0}}
    octree = tileset_json({
        "geometricError": 10, "boundingVolume": {"box": [0, 0, 0, 2, 0, 0, 0, 4, 0, 0, 0, 6]},
        "content": {"uri": "o/{level}/{x}/{y}/{z}.pnts"},
        "implicitTiling": dict(implicit, subdivisionScheme="OCTREE", availableLevels=2)})
    liberal = json.dumps({"asset": {}, "geometricError": 50, "root": {
        "refine": "add", "boundingVolume": {"box": [0, 0, 0, 4, 0, 0, 0, 4, 0, 0, 0, 4]},
        "content": {"url": "a.glb", "boundingVolume": {"sphere": [0, 0, 0, 3]}},
        "children": [
            {"refine": "Replace", "boundingVolume": {"sphere": [9, 0, 0, 2]},
             "content": {"uri": ""},
             "children": [{"refine": "MERGE", "boundingVolume": {"sphere": [9, 0, 0, 1]},
                           "content": {"uri": "b.glb"}}]},
            {"geometricError": 1, "boundingVolume": {"sphere": [0, 0, 0, 1]},
             "viewerRequestVolume": {"sphere": [0, 0, 0, 10]},
             "content": {"uri": "c.glb"}}]}}, separators=(",", ":")).encode()
    return [
        listed + b"\0" + tileset_record("e.json", external),
        liberal + b"\0",
        boxes + b"\0" + tileset_record("s000.subtree", root_subtree) +
        tileset_record("s232.subtree", child_subtree) + tileset_record("b.bin", b"\x01"),
        regions + b"\0" + tileset_record("s000.subtree", json.dumps({
            "buffers": [{"uri": "b.bin", "byteLength": 1}],
            "bufferViews": [{"buffer": 0, "byteLength": 1}],
            "tileAvailability": {"constant": 1}, "contentAvailability": [{"constant": 1}],
            "childSubtreeAvailability": {"bitstream": 0}})) +
        tileset_record("b.bin", b"\x06") +
        tileset_record("s110.subtree", json.dumps(dict(
            everything, contentAvailability=[{"constant": 0}]))) +
        tileset_record("s101.subtree", binary_subtree(everything, b"")),
        octree + b"\0" + tileset_record("s000.subtree", json.dumps(everything)),
    ]


def write(directory, seeds):
    os.makedirs(directory, exist_ok=True)
    for data in seeds:
        name = hashlib.sha1(data).hexdigest()
        with open(os.path.join(directory, name), "wb") as f:
            f.write(data)
        print(os.path.join(directory, name), len(data))


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "corpus")
    write(os.path.join(root, "select"), select_seeds())
    write(os.path.join(root, "schedule"), schedule_seeds())
    write(os.path.join(root, "stream"), stream_seeds())
    write(os.path.join(root, "tileset"), tileset_seeds())


if __name__ == "__main__":
    main()
