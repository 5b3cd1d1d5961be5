// The outside implementation the test suite compares shadergen with (docs/gltf.md, "Against
// three.js"): three.js's GLTFLoader, AnimationMixer and CPU skinning/morphing
// (Mesh.getVertexPosition) pose a model at given times and print every mesh primitive's
// posed world positions (and normals) as JSON.
//
//   node three_pose.mjs MODEL.glb|.gltf --animation NAME|INDEX --time T [--time T2 ...]
//   node three_pose.mjs --check-saved DIR   (loads validate --save-outputs' .glb files back,
//                                            checks them with the Khronos glTF-Validator and
//                                            their positions against the .bin arrays)
//
// In Node there is no DOM: the loader cannot decode images. Images, textures and samplers
// are removed and every material emptied before parsing (positions and normals do not read
// them); a .gltf's buffers (files or data URIs) are read here and packed with its JSON into
// one GLB, so the loader fetches nothing.
import { readFileSync, existsSync } from 'node:fs';
import { dirname, join } from 'node:path';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

function fail(message) {
  process.stderr.write(`three_pose.mjs: error: ${message}\n`);
  process.exit(1);
}

// The model as one GLB (JSON + one BIN chunk), images and materials stripped.
function packedGlb(file) {
  const bytes = readFileSync(file);
  let json;
  const buffers = [];
  if (bytes.readUInt32LE(0) === 0x46546c67) {
    let at = 12;
    while (at < bytes.length) {
      const len = bytes.readUInt32LE(at), type = bytes.readUInt32LE(at + 4);
      const chunk = bytes.subarray(at + 8, at + 8 + len);
      if (type === 0x4e4f534a) json = JSON.parse(chunk.toString('utf8'));
      else if (type === 0x004e4942) buffers.push(chunk);
      at += 8 + len;
    }
    (json.buffers || []).forEach((b, i) => {
      if (b.uri !== undefined) buffers[i] = bufferFromUri(file, b.uri);
    });
  } else {
    json = JSON.parse(bytes.toString('utf8'));
    (json.buffers || []).forEach((b, i) => buffers.push(bufferFromUri(file, b.uri)));
  }
  // One buffer: each source buffer at a 4-aligned offset.
  const offsets = [];
  let total = 0;
  for (const b of buffers) {
    offsets.push(total);
    total += Math.ceil(b.length / 4) * 4;
  }
  const bin = Buffer.alloc(total);
  buffers.forEach((b, i) => b.copy(bin, offsets[i]));
  for (const v of json.bufferViews || []) {
    v.byteOffset = (v.byteOffset || 0) + offsets[v.buffer];
    v.buffer = 0;
  }
  json.buffers = total > 0 ? [{ byteLength: total }] : [];
  delete json.images;
  delete json.textures;
  delete json.samplers;
  if (json.materials) json.materials = json.materials.map(() => ({}));
  const text = Buffer.from(JSON.stringify(json), 'utf8');
  const jsonChunk = Buffer.concat([text, Buffer.alloc((4 - (text.length % 4)) % 4, 0x20)]);
  const header = Buffer.alloc(12);
  header.writeUInt32LE(0x46546c67, 0);
  header.writeUInt32LE(2, 4);
  header.writeUInt32LE(12 + 8 + jsonChunk.length + (total > 0 ? 8 + total : 0), 8);
  const chunkHeader = (len, type) => {
    const h = Buffer.alloc(8);
    h.writeUInt32LE(len, 0);
    h.writeUInt32LE(type, 4);
    return h;
  };
  const parts = [header, chunkHeader(jsonChunk.length, 0x4e4f534a), jsonChunk];
  if (total > 0) parts.push(chunkHeader(total, 0x004e4942), bin);
  const glb = Buffer.concat(parts);
  return glb.buffer.slice(glb.byteOffset, glb.byteOffset + glb.length);
}

function bufferFromUri(file, uri) {
  if (uri.startsWith('data:')) return Buffer.from(uri.slice(uri.indexOf(',') + 1), 'base64');
  const path = join(dirname(file), decodeURIComponent(uri));
  if (!existsSync(path)) fail(`${file}: buffer '${uri}' not found`);
  return readFileSync(path);
}

function load(arrayBuffer) {
  return new Promise((resolve, reject) => new GLTFLoader().parse(arrayBuffer, '', resolve, reject));
}

// Every mesh primitive under its node, as (node, mesh, primitive).
function meshesOf(gltf) {
  const out = [];
  gltf.scene.traverse((o) => {
    if (!o.isMesh) return;
    const a = gltf.parser.associations.get(o) || {};
    const node = a.nodes !== undefined ? a.nodes : (gltf.parser.associations.get(o.parent) || {}).nodes;
    out.push({ object: o, node, mesh: a.meshes, primitive: a.primitives === undefined ? 0 : a.primitives });
  });
  return out;
}

// World positions and normals of one mesh as three poses it on the CPU.
// Positions: Mesh.getVertexPosition (morph targets, then SkinnedMesh.applyBoneTransform), then
// the object's world matrix. Normals (three has no CPU helper): what its vertex shader does
// (morphnormal_vertex, skinnormal_vertex, then the normal matrix), in world space:
//   n = normal + Σ w_i · morphNormal_i  (glTF targets are relative)
//   skinned: n = mat3(bindMatrixInverse · Σ_k weight_k · boneWorld_k · boneInverse_k · bindMatrix) · n
//   world: normalize(transpose(inverse(mat3(matrixWorld))) · n)
function posedMesh(o) {
  const g = o.geometry;
  const count = g.attributes.position.count;
  const positions = new Array(count * 3);
  const p = new THREE.Vector3();
  for (let i = 0; i < count; i++) {
    o.getVertexPosition(i, p);
    p.applyMatrix4(o.matrixWorld);
    positions[3 * i] = p.x;
    positions[3 * i + 1] = p.y;
    positions[3 * i + 2] = p.z;
  }
  let normals = null;
  if (g.attributes.normal) {
    normals = new Array(count * 3);
    const n = new THREE.Vector3(), d = new THREE.Vector3();
    const normalMatrix = new THREE.Matrix3().getNormalMatrix(o.matrixWorld);
    const morphs = g.morphAttributes.normal;
    const influences = o.morphTargetInfluences;
    const skinIndex = new THREE.Vector4(), skinWeight = new THREE.Vector4();
    const m = new THREE.Matrix4(), sum = new THREE.Matrix4(), bone = new THREE.Matrix4();
    for (let i = 0; i < count; i++) {
      n.fromBufferAttribute(g.attributes.normal, i);
      if (morphs && influences) {
        for (let t = 0; t < morphs.length; t++) {
          if (!influences[t]) continue;
          d.fromBufferAttribute(morphs[t], i);
          n.addScaledVector(d, g.morphTargetsRelative ? influences[t] : influences[t]);
        }
      }
      if (o.isSkinnedMesh) {
        skinIndex.fromBufferAttribute(g.attributes.skinIndex, i);
        skinWeight.fromBufferAttribute(g.attributes.skinWeight, i);
        sum.set(0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0);
        for (let k = 0; k < 4; k++) {
          const w = skinWeight.getComponent(k);
          if (w === 0) continue;
          const j = skinIndex.getComponent(k);
          bone.multiplyMatrices(o.skeleton.bones[j].matrixWorld, o.skeleton.boneInverses[j]);
          for (let e = 0; e < 16; e++) sum.elements[e] += w * bone.elements[e];
        }
        m.multiplyMatrices(o.bindMatrixInverse, sum).multiply(o.bindMatrix);
        n.transformDirection(m);  // mat3(m) · n, normalized
      }
      n.applyMatrix3(normalMatrix).normalize();
      normals[3 * i] = n.x;
      normals[3 * i + 1] = n.y;
      normals[3 * i + 2] = n.z;
    }
  }
  return { positions, normals };
}

// The glTF spec requires unit rotation quaternions; three.js uses stored ones as they are
// (Object3D.quaternion, and QuaternionKeyframeTrack values, whose slerp keeps their length),
// so a stored length of 0.99985 (SimpleSkin's keyframes) scales the joint by it. shadergen
// normalises them, as the spec intends; here they are normalised after loading so the
// comparison measures posing, not that asset defect (docs/gltf.md, "Against three.js").
function normaliseQuaternions(gltf) {
  gltf.scene.traverse((o) => o.quaternion.normalize());
  for (const clip of gltf.animations)
    for (const track of clip.tracks) {
      // CUBICSPLINE tracks hold tangents too; three normalises their result already.
      if (track.ValueTypeName !== 'quaternion' || track.createInterpolant.isInterpolantFactoryMethodGLTFCubicSpline) continue;
      const v = track.values;
      for (let i = 0; i + 3 < v.length; i += 4) {
        const len = Math.hypot(v[i], v[i + 1], v[i + 2], v[i + 3]);
        if (len > 0) for (let c = 0; c < 4; c++) v[i + c] /= len;
      }
    }
}

async function pose(file, animation, times) {
  const gltf = await load(packedGlb(file));
  normaliseQuaternions(gltf);
  const clips = gltf.animations;
  let clip = null;
  if (clips.length > 0) {
    if (animation === undefined || animation === '') clip = clips[0];
    else clip = clips.find((c) => c.name === animation) || (/^\d+$/.test(animation) ? clips[Number(animation)] : null);
    if (!clip) fail(`${file}: no animation '${animation}'`);
  }
  const mixer = new THREE.AnimationMixer(gltf.scene);
  if (clip) mixer.clipAction(clip).play();
  const result = { model: file, animation: clip ? clip.name : '', duration: clip ? clip.duration : 0, poses: [] };
  for (const t of times) {
    mixer.setTime(t);
    gltf.scene.updateMatrixWorld(true);
    const meshes = meshesOf(gltf).map((m) => {
      const posed = posedMesh(m.object);
      return {
        node: m.node,
        mesh: m.mesh,
        primitive: m.primitive,
        skinned: !!m.object.isSkinnedMesh,
        mesh_world_is_identity: m.object.matrixWorld.equals(new THREE.Matrix4()),
        positions: posed.positions,
        normals: posed.normals,
      };
    });
    result.poses.push({ time: t, meshes });
  }
  return result;
}

// validate --save-outputs' glTF files loaded back: each passes the Khronos glTF-Validator
// with no error or warning, and every instance node's POSITION equals the .bin of the output
// it was written from, float for float.
async function checkSaved(dir) {
  const validator = (await import('gltf-validator')).default;
  const index = JSON.parse(readFileSync(join(dir, 'outputs.json'), 'utf8'));
  let files = 0, meshes = 0;
  for (const prim of index.primitives) {
    for (const g of prim.gltf) {
      const bytes = readFileSync(join(dir, g.file));
      const report = await validator.validateBytes(new Uint8Array(bytes));
      if (report.issues.numErrors + report.issues.numWarnings > 0)
        fail(`${g.file}: the glTF-Validator reports ${JSON.stringify(report.issues.messages)}`);
      const gltf = await load(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length));
      const found = meshesOf(gltf);
      if (found.length !== prim.instances.length)
        fail(`${g.file}: ${found.length} meshes, ${prim.instances.length} instances in outputs.json`);
      for (const m of found) {
        const instance = m.node;  // node i draws instance i
        const entry = prim.arrays.find((a) => a.instance === instance && a.time_index === g.time_index && a.output === g.position);
        if (!entry) fail(`${g.file}: no array for instance ${instance}`);
        const raw = readFileSync(join(dir, entry.file));
        const bin = new Float32Array(raw.buffer.slice(raw.byteOffset, raw.byteOffset + raw.length));
        const pos = m.object.geometry.attributes.position;
        if (pos.count !== entry.count) fail(`${g.file}: instance ${instance} has ${pos.count} positions, ${entry.file} ${entry.count}`);
        for (let v = 0; v < pos.count; v++)
          for (let c = 0; c < 3; c++) {
            const a = pos.array[v * 3 + c], b = bin[v * entry.components + c];
            if (!(a === b || (Number.isNaN(a) && Number.isNaN(b))))
              fail(`${g.file}: instance ${instance} vertex ${v} [${c}] is ${a}, ${entry.file} has ${b}`);
          }
        meshes++;
      }
      files++;
    }
  }
  process.stdout.write(JSON.stringify({ files, meshes }) + '\n');
}

const args = process.argv.slice(2);
if (args[0] === '--check-saved') {
  await checkSaved(args[1]);
} else {
  const times = [];
  let animation, file;
  for (let i = 0; i < args.length; i++) {
    if (args[i] === '--time') times.push(Number(args[++i]));
    else if (args[i] === '--animation') animation = args[++i];
    else file = args[i];
  }
  if (!file) fail('usage: three_pose.mjs MODEL [--animation A] --time T ...');
  if (times.length === 0) times.push(0);
  process.stdout.write(JSON.stringify(await pose(file, animation, times)) + '\n');
}
