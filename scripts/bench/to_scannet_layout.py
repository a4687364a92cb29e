#!/usr/bin/env python3
"""Writes a panmap-synth ground-truth mesh as a ScanNet scene folder of the current release,
so that a procedural scene of any size and layout (a multi-room floor, say) runs through
`panmap-synth --scannet` and the accuracy suite's `--scannet` path like a downloaded scene:

    python3 scripts/bench/to_scannet_layout.py OUT/gt/mesh.ply SCENE_DIR scene0907_00

Writes SCENE_DIR/scene0907_00_vh_clean_2.ply (mesh), _vh_clean_2.labels.ply (`label` = the
ScanNet id of a raw category of the vertex's NYU40 class, as current releases store it),
_vh_clean_2.0.010000.segs.json (one segment per instance) and .aggregation.json (one segGroup
per annotated instance, labelled with that raw category). Vertices without a class or
instance stay out of every group, as ScanNet's unannotated ones do. The label table is
../shared/data/scannet-meta/scannetv2-labels.combined.tsv (or --labels TSV as a 4th argument).
"""
import json, os, sys, struct
from collections import Counter, defaultdict
if len(sys.argv) not in (4, 5):
    sys.exit(__doc__)
src, out, name = sys.argv[1], sys.argv[2], sys.argv[3]
root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
tsv = sys.argv[4] if len(sys.argv) == 5 else os.path.join(
    root, "..", "shared", "data", "scannet-meta", "scannetv2-labels.combined.tsv")
rows = [l.rstrip("\n").split("\t") for l in open(tsv)]
head = rows[0]; rows = rows[1:]
ci, craw, cnyu = head.index("id"), head.index("raw_category"), head.index("nyu40id")
raw_of, sid_of = {}, {}
for r in sorted(rows, key=lambda r: int(r[ci])):
    if len(r) <= cnyu or not r[cnyu]: continue
    n = int(r[cnyu])
    if n not in raw_of: raw_of[n] = r[craw]; sid_of[n] = int(r[ci])
data = open(src, "rb").read()
end = data.index(b"end_header\n") + len(b"end_header\n")
hdr = data[:end].decode()
nv = int(hdr.split("element vertex ")[1].split()[0]); nf = int(hdr.split("element face ")[1].split()[0])
V = struct.Struct("<fffBBBii")
verts = [V.unpack_from(data, end + k * V.size) for k in range(nv)]
faces = data[end + nv * V.size:]
if "property int semantic" not in hdr or len(faces) != nf * 13:
    sys.exit("to_scannet_layout: %s is not a panmap-synth gt/mesh.ply (x y z rgb semantic "
             "instance, triangles)" % src)
os.makedirs(out, exist_ok=True)
def write_ply(path, with_label):
    props = "property float x\nproperty float y\nproperty float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n"
    if with_label: props += "property ushort label\n"
    h = ("ply\nformat binary_little_endian 1.0\ncomment MLIB generated\nelement vertex %d\n%selement face %d\nproperty list uchar int vertex_indices\nend_header\n" % (nv, props, nf))
    W = struct.Struct("<fffBBBBH" if with_label else "<fffBBBB")
    buf = bytearray()
    for (x, y, z, r, g, b, sem, inst) in verts:
        if with_label:
            buf += W.pack(x, y, z, r, g, b, 255, sid_of.get(sem, 0) if sem > 0 else 0)
        else:
            buf += W.pack(x, y, z, r, g, b, 255)
    with open(path, "wb") as fo:
        fo.write(h.encode()); fo.write(buf); fo.write(faces)
write_ply(os.path.join(out, name + "_vh_clean_2.ply"), False)
write_ply(os.path.join(out, name + "_vh_clean_2.labels.ply"), True)
seg = [inst if sem > 0 and inst > 0 else 10**6 + max(inst, 0) for (*_, sem, inst) in verts]
json.dump({"sceneId": name, "segThresh": 0.01, "segIndices": seg},
          open(os.path.join(out, name + "_vh_clean_2.0.010000.segs.json"), "w"))
cls = defaultdict(Counter)
for (*_, sem, inst) in verts:
    if sem > 0 and inst > 0: cls[inst][sem] += 1
groups = [{"id": k, "objectId": k, "segments": [inst], "label": raw_of[c.most_common(1)[0][0]]}
          for k, (inst, c) in enumerate(sorted(cls.items()))]
json.dump({"sceneId": "scannet." + name, "appId": "converted", "segGroups": groups,
           "segmentsFile": "scannet." + name + "_vh_clean_2.0.010000.segs.json"},
          open(os.path.join(out, name + ".aggregation.json"), "w"), indent=1)
print(nv, "vertices", nf, "faces", len(groups), "objects")
