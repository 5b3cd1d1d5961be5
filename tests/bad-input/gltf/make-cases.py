#!/usr/bin/env python3
"""Writes the glTF cases of the bad-input corpus (tests/bad-input/gltf/<case>/).

Each case is a small hostile model plus `run` (shadergen arguments) and `expect` (exit status,
then strings stderr must contain). Rerun after changing a case here; the files are committed
so that the corpus needs no Python.
"""
import base64
import json
import os
import shutil
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
TRI = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)


def data_uri(b):
    return "data:application/octet-stream;base64," + base64.b64encode(b).decode()


def model(accessors, views=None, blob=TRI, extra=None, uri=None, byte_length=None):
    """A glTF dict with one buffer (data URI unless `uri`), one triangle mesh on node 0."""
    m = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(blob) if byte_length is None else byte_length,
                     "uri": data_uri(blob) if uri is None else uri}],
        "bufferViews": views if views is not None else [{"buffer": 0, "byteLength": len(blob)}],
        "accessors": accessors,
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}],
    }
    m.update(extra or {})
    return m


POS = {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}


def pos(**kw):
    a = dict(POS)
    a.update(kw)
    return a


def glb(js, bin_bytes, bin_len_field=None, total_field=None, magic=b"glTF", version=2):
    j = json.dumps(js).encode()
    j += b" " * (-len(j) % 4)
    out = magic + struct.pack("<II", version, 0) + struct.pack("<I", len(j)) + b"JSON" + j
    if bin_bytes is not None:
        out += struct.pack("<I", len(bin_bytes) if bin_len_field is None else bin_len_field) + b"BIN\0" + bin_bytes
    total = len(out) if total_field is None else total_field
    return out[:8] + struct.pack("<I", total) + out[12:]


cases = {}


def case(name, files, run, status, *messages, setup=None):
    cases[name] = (files, run, status, messages, setup)


def rig_import(path):
    return f"rig import {path} -o @O/rig.yaml"


def text(m):
    return json.dumps(m, indent=1).encode()


# --- bounds arithmetic -------------------------------------------------------------------
case("accessor-offset-wraps", {"m.gltf": text(model([pos(byteOffset=18446744073709551600)]))},
     rig_import("@D/m.gltf"), 1, "@D/m.gltf: error:", "reads bytes 18446744073709551600..+36 of buffer view 0, which has 36 bytes")
case("view-offset-wraps",
     {"m.gltf": text(model([POS], views=[{"buffer": 0, "byteOffset": 18446744073709551615, "byteLength": 36}]))},
     rig_import("@D/m.gltf"), 1, "@D/m.gltf: error:", "lies outside buffer 0 (36 bytes)")
case("view-past-buffer", {"m.gltf": text(model([POS], views=[{"buffer": 0, "byteOffset": 8, "byteLength": 36}]))},
     rig_import("@D/m.gltf"), 1, "buffer view 0 (bytes 8..+36) lies outside buffer 0 (36 bytes)")
case("count-billion", {"m.gltf": text(model([pos(count=1000000000)]))},
     rig_import("@D/m.gltf"), 1, "has 1000000000 elements; the limit is 16777216")
case("count-past-view", {"m.gltf": text(model([pos(count=16000000)]))},
     rig_import("@D/m.gltf"), 1, "reads bytes 0..+192000000 of buffer view 0, which has 36 bytes")
zero_fill = model([{"componentType": 5126, "count": 16000000, "type": "VEC3"}])
case("count-zero-fill", {"m.gltf": text(zero_fill)}, rig_import("@D/m.gltf"), 1,
     "decoding 16000000 elements would take the decoded data past this model's limit of 64.")
case("stride-below-element", {"m.gltf": text(model([POS], views=[{"buffer": 0, "byteLength": 36, "byteStride": 4}]))},
     rig_import("@D/m.gltf"), 1, "has byteStride 4, less than the 12-byte element")
case("view-missing", {"m.gltf": text(model([pos(bufferView=7)]))}, rig_import("@D/m.gltf"), 1,
     "refers to buffer view 7, which does not exist")
case("accessor-missing", {"m.gltf": text(model([POS], extra={
    "meshes": [{"primitives": [{"attributes": {"POSITION": 3}}]}]}))}, rig_import("@D/m.gltf"), 1,
     "attribute POSITION refers to accessor 3, which does not exist")

SPARSE_BLOB = TRI + struct.pack("<HH", 0, 1) + struct.pack("<6f", 1, 1, 1, 2, 2, 2)
SPARSE_VIEWS = [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 4},
                {"buffer": 0, "byteOffset": 40, "byteLength": 24}]


def sparse(count, idx_offset=0, idx_type=5123):
    return model([pos(sparse={"count": count,
                              "indices": {"bufferView": 1, "componentType": idx_type, "byteOffset": idx_offset},
                              "values": {"bufferView": 2}})], views=SPARSE_VIEWS, blob=SPARSE_BLOB)


case("sparse-count-negative", {"m.gltf": text(sparse(-2147483648))}, rig_import("@D/m.gltf"), 1,
     "sparse count -2147483648 is not between 0 and the accessor's count 3")
case("sparse-count-above-count", {"m.gltf": text(sparse(4))}, rig_import("@D/m.gltf"), 1,
     "sparse count 4 is not between 0 and the accessor's count 3")
case("sparse-indices-offset", {"m.gltf": text(sparse(2, idx_offset=2147483647))}, rig_import("@D/m.gltf"), 1,
     "sparse indices reads bytes 2147483647..+4 of buffer view 1")
case("sparse-index-out-of-range", {"m.gltf": text(model(
    [pos(sparse={"count": 1, "indices": {"bufferView": 1, "componentType": 5123},
                 "values": {"bufferView": 2}})], views=SPARSE_VIEWS,
    blob=TRI + struct.pack("<HH", 9, 0) + struct.pack("<6f", 1, 1, 1, 2, 2, 2)))}, rig_import("@D/m.gltf"), 1,
     "sparse index 9 is out of range (count 3)")
case("sparse-index-type-float", {"m.gltf": text(sparse(1, idx_type=5126))}, rig_import("@D/m.gltf"), 1,
     "sparse indices must be unsigned byte, short or int")
case("joints-set-number-overflows", {"m.gltf": text(model([POS], extra={
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_99999999999": 0}}]}]}))}, rig_import("@D/m.gltf"), 1,
     "has JOINTS_99999999999 (4000004 influences per vertex); the rules serve at most 16")
case("position-nan", {"m.gltf": text(model([POS], blob=struct.pack("<9f", 0, 0, 0, float("nan"), 0, 0, 0, 1, 0)))},
     rig_import("@D/m.gltf"), 1, "holds a non-finite value")

# --- skin weights, joints, quaternions, frames, instancing (docs/gltf.md#import-diagnostics-and-weights)
# A skinned triangle on node 0 (skin 0: joints nodes 1 and 2), an animation rotating node 2.
# Valid but suspect data warns (exit 0; -Werror makes it exit 1 and write nothing); data no
# program can use is an error.
def skinned(weights=((1, 0, 0, 0),) * 3, joints=((0, 1, 0, 0),) * 3, weight_type=5126, rotation=None,
            keys=((0, 0, 0, 1), (0, 0.7071068, 0, 0.7071068)), normals=None, tangents=None, nodes=None, skins=None):
    parts, views, accessors = [], [], []

    def add(data, **acc):
        off = sum(len(x) for x in parts)
        parts.append(data + b"\0" * (-len(data) % 4))
        views.append({"buffer": 0, "byteOffset": off, "byteLength": len(data)})
        accessors.append(dict(acc, bufferView=len(views) - 1))
        return len(accessors) - 1

    attrs = {"POSITION": add(TRI, componentType=5126, count=3, type="VEC3")}
    attrs["JOINTS_0"] = add(struct.pack("<12B", *[j for v in joints for j in v]), componentType=5121,
                            count=len(joints), type="VEC4")
    flat = [w for v in weights for w in v]
    if weight_type == 5126:
        attrs["WEIGHTS_0"] = add(struct.pack(f"<{len(flat)}f", *flat), componentType=5126, count=len(weights), type="VEC4")
    else:
        attrs["WEIGHTS_0"] = add(struct.pack(f"<{len(flat)}B", *flat), componentType=5121, normalized=True,
                                 count=len(weights), type="VEC4")
    if normals:
        attrs["NORMAL"] = add(struct.pack("<9f", *[c for v in normals for c in v]), componentType=5126, count=3, type="VEC3")
    if tangents:
        attrs["TANGENT"] = add(struct.pack("<12f", *[c for v in tangents for c in v]), componentType=5126, count=3,
                               type="VEC4")
    times = add(struct.pack("<2f", 0, 1), componentType=5126, count=2, type="SCALAR", min=[0], max=[1])
    rots = add(struct.pack("<8f", *[c for q in keys for c in q]), componentType=5126, count=2, type="VEC4")
    blob = b"".join(parts)
    joint_node = {"rotation": list(rotation)} if rotation else {}
    return {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(blob), "uri": data_uri(blob)}],
        "bufferViews": views, "accessors": accessors,
        "meshes": [{"name": "tri", "primitives": [{"attributes": attrs}]}],
        "nodes": nodes or [{"mesh": 0, "skin": 0}, {"children": [2]}, joint_node],
        "skins": skins or [{"joints": [1, 2]}],
        "scenes": [{"nodes": [0, 1]}],
        "animations": [{"samplers": [{"input": times, "output": rots}],
                        "channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}}]}],
    }


GEN = "generate --rig @D/m.gltf -f tests/gltf/data/minimal.frag -r rules/standard.yaml -o @O/tri"
W = "@D/m.gltf: warning: mesh 'tri' primitive 0, "
case("weights-sum-above-one", {"m.gltf": text(skinned(weights=((0.9, 0.6, 0, 0), (1, 0, 0, 0), (0.5, 0.5, 0, 0))))},
     rig_import("@D/m.gltf"), 0,
     W + "WEIGHTS_0 (accessor 2, /meshes/0/primitives/0/attributes/WEIGHTS_0): the weights of 1 of 3 vertices do not "
     "sum to 1 (first: vertex 0; the farthest from 1: 1.5); renormalised to sum to 1",
     "(--no-normalize-weights keeps them) [ACCESSOR_WEIGHTS_NON_NORMALIZED]")
case("weights-sum-werror", {"m.gltf": text(skinned(weights=((0.9, 0.6, 0, 0),) * 3))}, GEN + " -Werror", 1,
     "@D/m.gltf: error: mesh 'tri' primitive 0, WEIGHTS_0 (accessor 2",
     "the weights of 3 of 3 vertices do not sum to 1", "(-Werror) [ACCESSOR_WEIGHTS_NON_NORMALIZED]")
case("weights-sum-kept", {"m.gltf": text(skinned(weights=((0.2, 0.3, 0, 0),) * 3))},
     rig_import("@D/m.gltf") + " --no-normalize-weights", 0,
     "the farthest from 1: 0.5); kept as stored (--no-normalize-weights): the skin there is scaled by the sum")
case("weights-all-zero", {"m.gltf": text(skinned(weights=((0, 0, 0, 0), (1, 0, 0, 0), (1, 0, 0, 0))))}, GEN, 0,
     "the weights of 1 of 3 vertices do not sum to 1 (first: vertex 0; the farthest from 1: 0)")
case("weights-negative", {"m.gltf": text(skinned(weights=((1.5, -0.5, 0, 0),) * 3))}, rig_import("@D/m.gltf"), 0,
     W + "WEIGHTS_0 (accessor 2, /meshes/0/primitives/0/attributes/WEIGHTS_0): 3 of 3 vertices have a negative weight "
     "(first: vertex 0); the program blends with it as stored [ACCESSOR_WEIGHTS_NEGATIVE]")
case("weights-unorm-sum-below", {"m.gltf": text(skinned(weights=((100, 100, 0, 0), (255, 0, 0, 0), (128, 127, 0, 0)),
                                                        weight_type=5121))},
     rig_import("@D/m.gltf"), 0, "the weights of 1 of 3 vertices do not sum to 1 (first: vertex 0; the farthest from 1: "
     "0.784314); renormalised")
case("weights-nan", {"m.gltf": text(skinned(weights=((float("nan"), 0, 0, 0),) * 3))}, GEN, 1,
     "WEIGHTS_0 (accessor 2) holds a non-finite value (/accessors/2) [ACCESSOR_INVALID_FLOAT]")
case("joints-out-of-range", {"m.gltf": text(skinned(joints=((0, 7, 0, 0),) * 3))}, GEN, 1,
     "@D/m.gltf: error: mesh 'tri' primitive 0: JOINTS_0 (accessor 1, /meshes/0/primitives/0/attributes/JOINTS_0) of "
     "vertex 0 is joint 7, but the skin has 2 joints [ACCESSOR_JOINTS_INDEX_OOB]")
case("joints-out-of-range-zero-weight", {"m.gltf": text(skinned(joints=((0, 1, 200, 0),) * 3))},
     rig_import("@D/m.gltf"), 1, "is joint 200, but the skin has 2 joints [ACCESSOR_JOINTS_INDEX_OOB]")
case("joints-weighted-twice", {"m.gltf": text(skinned(joints=((1, 1, 0, 0),) * 3, weights=((0.5, 0.5, 0, 0),) * 3))},
     rig_import("@D/m.gltf"), 0,
     "JOINTS_0 (accessor 1, /meshes/0/primitives/0/attributes/JOINTS_0): 3 of 3 vertices weight one joint twice "
     "(first: vertex 0, joint 1); a linear blend adds the two weights [ACCESSOR_JOINTS_INDEX_DUPLICATE]")
case("quaternion-node-short", {"m.gltf": text(skinned(rotation=(0, 0, 0, 0.9)))}, rig_import("@D/m.gltf"), 0,
     "@D/m.gltf: warning: node 2 ('', /nodes/2/rotation): the rotation quaternion has length 0.9, not 1; it is "
     "normalised before use [ROTATION_NON_UNIT]")
case("quaternion-node-zero", {"m.gltf": text(skinned(rotation=(0, 0, 0, 0)))}, rig_import("@D/m.gltf"), 1,
     "@D/m.gltf: error: node 2 ('', /nodes/2/rotation): the rotation quaternion has length 0: it is no rotation")
case("quaternion-sampler-long", {"m.gltf": text(skinned(keys=((0, 0, 0, 1), (0, 0.8, 0, 0.8))))}, GEN, 0,
     "@D/m.gltf: warning: animation '0' channel 0 (node 2 rotation, sampler 0, output accessor 4, /animations/0/channels/0/sampler): "
     "1 of 2 "
     "keyframe quaternions are not of unit length (first: keyframe 1; the farthest from 1: length 1.13137)",
     "[ACCESSOR_ANIMATION_SAMPLER_OUTPUT_NON_NORMALIZED_QUATERNION]")
case("quaternion-sampler-zero", {"m.gltf": text(skinned(keys=((0, 0, 0, 1), (0, 0, 0, 0))))}, GEN, 1,
     "@D/m.gltf: error: animation '0' channel 0 (node 2 rotation, sampler 0, output accessor 4, /animations/0/channels/0/sampler): "
     "keyframe 1 "
     "is a quaternion of length 0: it is no rotation")
case("normal-zero-tangent-sign", {"m.gltf": text(skinned(normals=((0, 0, 1), (0, 0, 0), (0, 0, 1)),
                                                         tangents=((1, 0, 0, 1), (1, 0, 0, 0), (1, 0, 0, -1))))},
     rig_import("@D/m.gltf"), 0,
     "NORMAL (accessor 3, /meshes/0/primitives/0/attributes/NORMAL): 1 of 3 vertices are not of unit length (first: "
     "vertex 1; the farthest from 1: length 0)", "[ACCESSOR_VECTOR3_NON_UNIT]",
     "TANGENT (accessor 4, /meshes/0/primitives/0/attributes/TANGENT): TANGENT.w of 1 of 3 vertices is not +1 or -1 "
     "(first: vertex 1, 0)", "[ACCESSOR_INVALID_SIGN]")
case("normal-zero-werror", {"m.gltf": text(skinned(normals=((0, 0, 1), (0, 0, 0), (0, 0, 1))))},
     rig_import("@D/m.gltf") + " --Werror", 1, "(-Werror) [ACCESSOR_VECTOR3_NON_UNIT]")
# Instancing: one mesh on two nodes with different skins; the second skin is too small for the
# joints the primitive uses, so that instance cannot be posed.
two_skins = skinned(joints=((0, 2, 0, 0),) * 3, nodes=[{"mesh": 0, "skin": 0}, {"children": [2, 3]}, {}, {},
                                                       {"mesh": 0, "skin": 1}],
                    skins=[{"joints": [1, 2, 3]}, {"joints": [1, 2]}])
two_skins["scenes"] = [{"nodes": [0, 1, 4]}]
case("instance-skin-too-small", {"m.gltf": text(two_skins)}, GEN, 1,
     "@D/m.gltf: error: mesh 'tri' primitive 0: JOINTS_0 (accessor 1, /meshes/0/primitives/0/attributes/JOINTS_0) of "
     "vertex 0 is joint 2, but skin 1 (of node 4) has 2 joints [ACCESSOR_JOINTS_INDEX_OOB]")
missing_skin = skinned(nodes=[{"mesh": 0, "skin": 0}, {"children": [2]}, {}, {"mesh": 0, "skin": 9}])
missing_skin["scenes"] = [{"nodes": [0, 1, 3]}]
case("instance-skin-missing", {"m.gltf": text(missing_skin)}, GEN, 1,
     "@D/m.gltf: error: node 3 instantiates mesh 'tri' with skin 9, which does not exist")
mixed = skinned(nodes=[{"mesh": 0, "skin": 0}, {"children": [2]}, {}, {"mesh": 0, "translation": [2, 0, 0]}])
mixed["scenes"] = [{"nodes": [0, 1, 3]}]
case("instance-skinned-and-rigid", {"m.gltf": text(mixed)}, GEN, 0)

# --- JSON ----------------------------------------------------------------------------------
deep = b'{"asset":{"version":"2.0"},\n"extras":' + b"[" * 5000 + b"]" * 5000 + b"}"
case("json-deep-nesting", {"m.gltf": deep}, rig_import("@D/m.gltf"), 1,
     "@D/m.gltf:2:73: error: JSON nested deeper than 64 levels")
case("json-syntax", {"m.gltf": b'{"asset":{"version":"2.0"},\n "meshes":[1,,2]}'}, rig_import("@D/m.gltf"), 1,
     "@D/m.gltf:2:14: error: invalid JSON: syntax error")
case("json-truncated", {"m.gltf": text(model([POS]))[:200]}, rig_import("@D/m.gltf"), 1, "error: invalid JSON")
case("json-not-object", {"m.gltf": b"[1, 2, 3]"}, rig_import("@D/m.gltf"), 1, "cannot load the glTF model")

# --- node hierarchy --------------------------------------------------------------------------
chain = [{"children": [i + 1]} for i in range(20000)] + [{"mesh": 0, "children": [0]}]
case("node-cycle-long", {"m.gltf": json.dumps(model([POS], extra={"nodes": chain})).encode()}, rig_import("@D/m.gltf"), 1,
     "is part of a cycle in the node hierarchy")
case("node-two-parents", {"m.gltf": text(model([POS], extra={"nodes": [{"children": [2]}, {"children": [2]}, {"mesh": 0}]}))},
     rig_import("@D/m.gltf"), 1, "node 2 has two parents")
case("node-child-missing", {"m.gltf": text(model([POS], extra={"nodes": [{"children": [-5]}, {"mesh": 0}]}))},
     rig_import("@D/m.gltf"), 1, "has a child -5 that does not exist")
case("scene-node-missing", {"m.gltf": text(model([POS], extra={"scenes": [{"nodes": [40]}]}))},
     rig_import("@D/m.gltf"), 1, "the scene refers to node 40, which does not exist")

# --- files --------------------------------------------------------------------------------
case("uri-parent-folder", {"model/m.gltf": text(model([POS], uri="../secret.bin")), "secret.bin": TRI},
     rig_import("@D/model/m.gltf"), 1, "secret.bin' lies outside the model's folder '@D/model'")
case("uri-encoded-parent", {"model/m.gltf": text(model([POS], uri="%2E%2E/secret.bin")), "secret.bin": TRI},
     rig_import("@D/model/m.gltf"), 1, "lies outside the model's folder '@D/model'")
case("uri-symlink-out", {"model/m.gltf": text(model([POS], uri="link.bin")), "secret.bin": TRI,
                         "model/link.bin": ("symlink", "../secret.bin")},
     rig_import("@D/model/m.gltf"), 1, "link.bin' lies outside the model's folder '@D/model'")
case("uri-absolute", {"m.gltf": text(model([POS], uri="/etc/passwd"))}, rig_import("@D/m.gltf"), 1,
     "@D/m.gltf: error: cannot load the glTF model: File not found : /etc/passwd")
case("uri-size-mismatch", {"m.gltf": text(model([POS], byte_length=4000000000))}, rig_import("@D/m.gltf"), 1,
     "Failed to decode 'uri'")
case("model-is-fifo", {}, rig_import("@T/fifo.gltf"), 1, "fifo.gltf: error: cannot read the glTF model: not a regular file",
     setup='mkfifo "$1/fifo.gltf"\n')
case("model-is-dev-zero", {}, rig_import("@T/zero.glb"), 1, "zero.glb: error: cannot read the glTF model: not a regular file",
     setup='ln -s /dev/zero "$1/zero.glb"\n')
case("model-is-directory", {}, rig_import("@T/dir.gltf"), 1, "dir.gltf: error: cannot read the glTF model: not a regular file",
     setup='mkdir "$1/dir.gltf"\n')
case("model-too-large", {}, rig_import("@T/huge.glb"), 1, "larger than the limit of 1024.0 MiB",
     setup='truncate -s 2G "$1/huge.glb"\n')

# A valid model whose one mesh hangs at the end of a 50,000-node chain (generated: 1 MB):
# the import, the pose and the baker's scene walk must not recurse per node. Succeeds.
CHAIN_SETUP = r"""awk 'BEGIN { n = 50000
  printf "{\"asset\":{\"version\":\"2.0\"},\"buffers\":[{\"byteLength\":36,\"uri\":\"data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],"
  printf "\"bufferViews\":[{\"buffer\":0,\"byteLength\":36}],\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":3,\"type\":\"VEC3\"}],"
  printf "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0}}]}],\"scenes\":[{\"nodes\":[0]}],\"nodes\":["
  for (i = 0; i < n - 1; i++) printf "{\"children\":[%d]},", i + 1
  printf "{\"mesh\":0}]}" }' > "$1/chain.gltf"
"""
case("bake-long-node-chain", {}, "bake occlusion @T/chain.gltf -o @O/baked.glb --rays 4 --threads 1", 0,
     setup=CHAIN_SETUP)
case("rig-import-long-node-chain", {}, "rig import @T/chain.gltf -o @O/rig.yaml", 0, setup=CHAIN_SETUP)

# --- GLB -----------------------------------------------------------------------------------
GLB_JSON = model([POS], extra={"buffers": [{"byteLength": 36}]})
case("glb-bin-chunk-overrun", {"m.glb": glb(GLB_JSON, TRI, bin_len_field=44)}, rig_import("@D/m.glb"), 1,
     "the GLB's BIN chunk at byte")
case("glb-length-lie", {"m.glb": glb(GLB_JSON, TRI, total_field=1 << 31)}, rig_import("@D/m.glb"), 1,
     "the GLB header claims 2147483648 bytes but the file has")
case("glb-json-chunk-overrun", {"m.glb": glb(GLB_JSON, TRI)[:12] + struct.pack("<I", 0xFFFFFFF0) + glb(GLB_JSON, TRI)[16:]},
     rig_import("@D/m.glb"), 1, "the GLB's first chunk must be JSON")
case("glb-bad-magic", {"m.glb": glb(GLB_JSON, TRI, magic=b"gLTF")}, rig_import("@D/m.glb"), 1, "no 'glTF' header")
case("glb-version-1", {"m.glb": glb(GLB_JSON, TRI, version=1)}, rig_import("@D/m.glb"), 1, "GLB version 1 is not supported")
deep_glb = b'{"x":' + b"[" * 70 + b"]" * 70 + b"}"
deep_glb += b" " * (-len(deep_glb) % 4)
case("glb-deep-json", {"m.glb": b"glTF" + struct.pack("<III", 2, 20 + len(deep_glb), len(deep_glb)) + b"JSON" + deep_glb},
     rig_import("@D/m.glb"), 1, "JSON nested deeper than 64 levels in the GLB's JSON chunk (line 1, column 69)")

# --- selection and the generate path ---------------------------------------------------------
case("mesh-index-missing", {"m.gltf": text(model([POS]))}, rig_import("@D/m.gltf#5/0"), 1, "there is no mesh 5")
case("selection-malformed", {"m.gltf": text(model([POS]))}, rig_import("@D/m.gltf#x/0"), 1,
     "does not select a primitive")
anim = model([POS, {"bufferView": 1, "componentType": 5126, "count": 2, "type": "SCALAR"},
              {"componentType": 5126, "count": 0, "type": "SCALAR"}],
             views=[{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 8}],
             blob=TRI + struct.pack("<2f", 0, 1),
             extra={"animations": [{"samplers": [{"input": 1, "output": 2}],
                                    "channels": [{"sampler": 0, "target": {"node": 0, "path": "weights"}}]}]})
case("animation-weights-empty", {"m.gltf": text(anim)}, rig_import("@D/m.gltf"), 1,
     "0 output values do not divide into 2 keyframes")
case("generate-with-hostile-rig", {"m.gltf": text(model([pos(byteOffset=18446744073709551600)]))},
     "generate --rig @D/m.gltf#0/0 -f examples/dawn/face.frag -r rules/standard.yaml -o @O/face", 1,
     "@D/m.gltf: error:", "reads bytes 18446744073709551600")

# Whole models (MODEL.glb#*, docs/gltf.md#whole-models).
two_meshes = model([POS, pos(byteOffset=18446744073709551600)], extra={
    "meshes": [{"name": "good", "primitives": [{"attributes": {"POSITION": 0}}]},
               {"name": "bad", "primitives": [{"attributes": {"POSITION": 1}}]}],
    "nodes": [{"mesh": 0}, {"mesh": 1}], "scenes": [{"nodes": [0, 1]}]})
case("whole-generate-hostile-primitive", {"m.gltf": text(two_meshes)},
     "generate --rig @D/m.gltf#* -f tests/gltf/data/minimal.frag -r rules/standard.yaml -o @O/shaders", 1,
     "@D/m.gltf#1/0: error: primitive m1p0-bad failed:", "reads bytes 18446744073709551600",
     "@D/m.gltf#*: error: 1 of 2 primitive(s) failed (m1p0-bad); nothing was written")
case("whole-rig-import-hostile-primitive", {"m.gltf": text(two_meshes)}, "rig import @D/m.gltf#* -o @O/rigs", 1,
     "primitive m1p0-bad failed", "1 of 2 primitive(s) failed (m1p0-bad); nothing was written")
no_meshes = {"asset": {"version": "2.0"}, "nodes": [{"name": "empty"}], "scenes": [{"nodes": [0]}]}
case("whole-no-meshes", {"m.gltf": text(no_meshes)},
     "validate --rig @D/m.gltf#* -f tests/gltf/data/minimal.frag -r rules/standard.yaml --time 0", 1,
     "@D/m.gltf: error: '@D/m.gltf#*' names every mesh primitive of the model, and it has none (0 mesh(es))")
case("whole-yaml-rig", {},
     "generate --rig examples/dawn/face.rig.yaml#* -f examples/dawn/face.frag -r rules/standard.yaml -o @O/shaders", 1,
     "error: '#*' selects every primitive of a glTF model (.gltf, .glb)")
case("whole-explain-takes-one", {"m.gltf": text(model([POS]))},
     "explain --rig @D/m.gltf#* -f tests/gltf/data/minimal.frag -r rules/standard.yaml", 1,
     "names every primitive of the model; this command takes one")
case("whole-rig-import-needs-output", {"m.gltf": text(model([POS]))}, "rig import @D/m.gltf#*", 2,
     "-o: is required with a whole model")
case("whole-rig-import-mesh-option", {"m.gltf": text(model([POS]))}, "rig import @D/m.gltf#* --mesh 0 -o @O/rigs", 2,
     "--mesh: does not apply")
many = model([POS], extra={"meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0}}] * 4097}]})
case("whole-too-many-primitives", {"m.gltf": json.dumps(many).encode()},
     "generate --rig @D/m.gltf#* -f tests/gltf/data/minimal.frag -r rules/standard.yaml -o @O/shaders", 1,
     "the model has 4097 mesh primitives; a whole model (#*) takes at most 4096 (kMaxGltfParts)")
case("whole-unknown-animation", {},
     "validate --rig tests/gltf/data/gltfpack/SimpleSkin.glb#* -f tests/gltf/data/minimal.frag "
     "-r rules/standard.yaml --animation Nope --time 0.5", 1,
     "SimpleSkin.glb: error: the model has no animation 'Nope' (it has ")
case("whole-selection-malformed", {"m.gltf": text(model([POS]))}, "rig import @D/m.gltf#** -o @O/rigs", 1,
     "'#**' does not select a primitive", "or MODEL.gltf#* (every primitive)")

# --- instances (one mesh under several nodes, each with its own skin) ------------------------
SKIN_BLOB = TRI + bytes([0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0]) + struct.pack("<12f", 1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0)
SKIN_VIEWS = [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 12},
              {"buffer": 0, "byteOffset": 48, "byteLength": 48}]
SKIN_ACCESSORS = [POS, {"bufferView": 1, "componentType": 5121, "count": 3, "type": "VEC4"},
                  {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC4"}]


def skinned_instances(second_skin_joints):
    """Node 0 draws the skinned triangle with skin 0 (2 joints: vertex 2 uses joint 1); node 1
    draws it with skin 1."""
    return model(SKIN_ACCESSORS, views=SKIN_VIEWS, blob=SKIN_BLOB, extra={
        "meshes": [{"name": "tri", "primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}}]}],
        "nodes": [{"mesh": 0, "skin": 0}, {"mesh": 0, "skin": 1}, {"name": "a"}, {"name": "b", "translation": [1, 0, 0]},
                  {"name": "c"}],
        "skins": [{"joints": [2, 3]}, {"joints": second_skin_joints}],
        "scenes": [{"nodes": [0, 1, 2, 3, 4]}]})


VALIDATE_TRI = "validate --rig @D/m.gltf -f tests/gltf/data/minimal.frag -r rules/standard.yaml --time 0"
# The import refuses it before posing (ACCESSOR_JOINTS_INDEX_OOB checks every skin instancing the mesh).
case("instance-skin-too-small-validate", {"m.gltf": text(skinned_instances([4]))}, VALIDATE_TRI, 1,
     "is joint 1, but skin 1 (of node 1) has 1 joints [ACCESSOR_JOINTS_INDEX_OOB]")
case("instance-render-skin-too-small", {"m.gltf": text(skinned_instances([4]))},
     "render --rig @D/m.gltf#* -f tests/gltf/data/minimal.frag -r rules/standard.yaml --size 8x8 -o @O/m.png", 1,
     "is joint 1, but skin 1 (of node 1) has 1 joints [ACCESSOR_JOINTS_INDEX_OOB]")
case("report-over-the-model", {"m.gltf": text(model([POS]))}, VALIDATE_TRI + " --report @D/m.gltf", 1,
     "output '@D/m.gltf' is the rig", "refusing to overwrite an input")
case("save-outputs-into-a-file", {"m.gltf": text(model([POS]))}, VALIDATE_TRI + " --save-outputs @D/m.gltf", 1,
     "cannot write '@D/m.gltf/")
case("report-on-a-yaml-rig", {},
     "validate --rig examples/dawn/face.rig.yaml -f examples/dawn/face.frag -r examples/dawn/rules.yaml --report @O/r.json",
     2, "--report", "to a YAML rig")


# --- EXT_mesh_gpu_instancing (a node's per-instance TRANSLATION / ROTATION / SCALE) ----------
INST_BLOB = (TRI + struct.pack("<6f", 0, 0, 0, 2, 0, 0) + struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 1)
             + struct.pack("<12H", 0, 0, 0, 65535, 0, 0, 0, 65535, 0, 0, 0, 65535))
INST_VIEWS = [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24},
              {"buffer": 0, "byteOffset": 60, "byteLength": 48}, {"buffer": 0, "byteOffset": 108, "byteLength": 24}]
INST_ACCESSORS = [POS, {"bufferView": 1, "componentType": 5126, "count": 2, "type": "VEC3"},  # 1: 2 translations
                  {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC4"},  # 2: 3 rotations, the 2nd zero
                  {"bufferView": 3, "componentType": 5123, "count": 3, "type": "VEC4", "normalized": True}]


def instanced(ext, required=False):
    """The triangle on node 0 with EXT_mesh_gpu_instancing `ext`."""
    m = model(INST_ACCESSORS, views=INST_VIEWS, blob=INST_BLOB,
              extra={"nodes": [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": ext}}]})
    if required:
        m["extensionsUsed"] = m["extensionsRequired"] = ["EXT_mesh_gpu_instancing"]
    return m


INST_AT = "@D/m.gltf: error: node 0 ('', /nodes/0/extensions/EXT_mesh_gpu_instancing"
case("gpu-instancing-required", {"m.gltf": text(instanced({"attributes": {"TRANSLATION": 1}}, required=True))},
     rig_import("@D/m.gltf"), 0)
case("gpu-instancing-count-mismatch", {"m.gltf": text(instanced({"attributes": {"TRANSLATION": 1, "ROTATION": 2}}))},
     VALIDATE_TRI, 1,
     INST_AT + "/attributes/ROTATION): ROTATION has 3 elements but TRANSLATION has 2; every attribute has one per "
     "instance")
case("gpu-instancing-rotation-unsigned", {"m.gltf": text(instanced({"attributes": {"ROTATION": 3}}))},
     rig_import("@D/m.gltf"), 1,
     INST_AT + "/attributes/ROTATION): ROTATION is normalized unsigned short VEC4; it must be VEC4 of float, or "
     "normalized byte or short")
case("gpu-instancing-translation-vec4", {"m.gltf": text(instanced({"attributes": {"TRANSLATION": 2}}))},
     rig_import("@D/m.gltf"), 1,
     INST_AT + "/attributes/TRANSLATION): TRANSLATION is float VEC4; it must be VEC3 of float, or byte or short")
case("gpu-instancing-rotation-zero", {"m.gltf": text(instanced({"attributes": {"ROTATION": 2}}))},
     rig_import("@D/m.gltf"), 1,
     INST_AT + "/attributes/ROTATION): instance 1 is a quaternion of length 0: it is no rotation")
case("gpu-instancing-accessor-missing", {"m.gltf": text(instanced({"attributes": {"SCALE": 9}}))},
     rig_import("@D/m.gltf"), 1, "/attributes/SCALE) refers to accessor 9, which does not exist")
case("gpu-instancing-accessor-not-index", {"m.gltf": text(instanced({"attributes": {"SCALE": "one"}}))},
     rig_import("@D/m.gltf"), 1, INST_AT + "/attributes/SCALE): SCALE is not an accessor index")
case("gpu-instancing-no-attributes", {"m.gltf": text(instanced({"attributes": {}}))}, rig_import("@D/m.gltf"), 1,
     INST_AT + "): its \"attributes\" have no TRANSLATION, ROTATION or SCALE")
case("gpu-instancing-attributes-missing", {"m.gltf": text(instanced({}))}, rig_import("@D/m.gltf"), 1,
     INST_AT + "): its \"attributes\" have no TRANSLATION, ROTATION or SCALE")


# `pack --rig rig.yaml --model M`: the model's skin is not the rig's import, so nothing checked
# its joints against the rig; joint 5 of a 6-joint skin was packed for a 2-bone palette.
TRI_RIG = b"""rig: "tri/tri/0"
deformers:
  bones: 2
  influences: 4
  morph_targets: 0
  uniform_scale: 1
attributes:
  position: { format: float32x3, provides: "vertex.position" }
  joints0: { format: uint8x4, provides: "skin.joints[0]" }
  weights0: { format: float32x4, provides: "skin.weights[0]" }
uniforms:
  bones: { type: mat4, array: bones, semantic: "skin.bones" }
  camera_position: { type: vec3, semantic: "camera.position" }
  view: { type: mat4, semantic: "camera.view" }
  projection: { type: mat4, semantic: "camera.projection" }
"""
case("pack-model-joints-past-rig",
     {"rig.yaml": TRI_RIG,
      "m.gltf": text(skinned(joints=((0, 5, 0, 0),) * 3, weights=((0.5, 0.5, 0, 0),) * 3,
                             nodes=[{"mesh": 0, "skin": 0}, {"children": [2, 3, 4, 5, 6, 7]}] + [{}] * 6,
                             skins=[{"joints": [2, 3, 4, 5, 6, 7]}]))},
     "pack --rig @D/rig.yaml --model @D/m.gltf -f tests/gltf/data/minimal.frag -r rules/standard.yaml -o @O/p", 1,
     "@D/rig.yaml:9:3: error: mesh 'm/tri/0' vertex 0 uses joint 5 (skin.joints[0]), but rig 'tri/tri/0' has 2 bones "
     "in 'joints0' stored as uint8x4: the model's skin is not the rig's")

# `pack --rig rig.yaml --model m.gltf -o m` beside the model: m.bin is the model's buffer file,
# an input, which pack overwrote (only the .gltf was checked).
RIGID_RIG = b"""rig: "m/tri/0"
attributes:
  position: { format: float32x3, provides: "vertex.position" }
uniforms:
  camera_position: { type: vec3, semantic: "camera.position" }
  view: { type: mat4, semantic: "camera.view" }
  projection: { type: mat4, semantic: "camera.projection" }
  model: { type: mat4, semantic: "model.matrix" }
"""
case("pack-output-is-model-buffer",
     {"rig.yaml": RIGID_RIG, "m.gltf": text(model([pos()], uri="m.bin")), "m.bin": TRI},
     "pack --rig @D/rig.yaml --model @D/m.gltf -f tests/gltf/data/minimal.frag -r rules/standard.yaml -o @D/m", 1,
     "shadergen: error: output '@D/m.bin' is an input ('@D/m.bin'); refusing to overwrite an input")

# The same for a glTF rig's own buffer file: validate's --report and --save-poses and render's
# -o were checked against the model file only.
EXTERNAL = {"m.gltf": text(model([pos()], uri="m.bin")), "m.bin": TRI}
for name, run in [("validate-report-is-model-buffer", "validate --rig @D/m.gltf --report @D/m.bin"),
                  ("validate-save-poses-is-model-buffer", "validate --rig @D/m.gltf --save-poses @D/m.bin"),
                  ("render-output-is-model-buffer", "render --rig @D/m.gltf -o @D/m.bin")]:
    case(name, EXTERNAL, run + " -f tests/gltf/data/minimal.frag -r rules/standard.yaml --no-validation-layers", 1,
         "shadergen: error: output '@D/m.bin' is the rig ('@D/m.bin'); refusing to overwrite an input")
case("calibrate-output-is-model-buffer", EXTERNAL,
     "calibrate --rig @D/m.gltf -f tests/gltf/data/minimal.frag -r rules/standard.yaml -o @D/m.bin --no-validation-layers", 1,
     "shadergen: error: output '@D/m.bin' is a rig ('@D/m.bin'); refusing to overwrite an input")
case("rig-import-output-is-model-buffer", EXTERNAL, "rig import @D/m.gltf -o @D/m.bin", 1,
     "shadergen: error: output '@D/m.bin' is the glTF model ('@D/m.bin'); refusing to overwrite an input")

def main():
    for name in sorted(os.listdir(HERE)):
        if os.path.isdir(os.path.join(HERE, name)) and name not in cases:
            shutil.rmtree(os.path.join(HERE, name))
    for name, (files, run, status, messages, setup) in cases.items():
        d = os.path.join(HERE, name)
        shutil.rmtree(d, ignore_errors=True)
        os.makedirs(d)
        for rel, content in files.items():
            p = os.path.join(d, rel)
            os.makedirs(os.path.dirname(p), exist_ok=True)
            if isinstance(content, tuple):
                os.symlink(content[1], p)
            else:
                with open(p, "wb") as f:
                    f.write(content)
        with open(os.path.join(d, "run"), "w") as f:
            f.write(run + "\n")
        with open(os.path.join(d, "expect"), "w") as f:
            f.write("\n".join([str(status), *messages]) + "\n")
        if setup:
            with open(os.path.join(d, "setup"), "w") as f:
                f.write(setup)
    print(f"{len(cases)} cases", file=sys.stderr)


main()
