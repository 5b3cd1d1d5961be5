#!/usr/bin/env bash
# Regenerates docs/comparison.md: for each Dawn example, the plan cost and the SPIR-V
# instruction count after `spirv-opt -O`, for (a) the plan shadergen chooses, (b) the
# "compute everything as listed" plan (listing 3-3's derivations forced by banning the
# alternatives), and for the face (c) a faithful hand port of listing 3-3.
# Usage: bench/compare_plans.sh [path/to/shadergen]   (default build/generator/cli/shadergen)
set -euo pipefail
cd "$(dirname "$0")/.."
sg=${1:-build/generator/cli/shadergen}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
ex=examples/dawn
# The listing's choices: per-vector linear blend skinning, N.V in eye space, the full
# dapple rotation, occlusion morphed together with the normal.
listed=(--ban skin_matrix_blend --ban world_position_from_matrix --ban world_normal_from_matrix
        --ban world_tangent_from_matrix --ban ndotv_world_space --ban dapple_normal_z_row
        --ban object_occlusion_morphed)

count() { spirv-dis "$1" | grep -cE '^\s*(%[A-Za-z0-9_]+ = )?Op'; }
cost() { "$sg" generate "$@" | sed -n 's/^  total cost //p'; }

row() {  # name rig frag [extra args]
  local name=$1 rig=$2 frag=$3; shift 3
  local c l
  c=$(cost --rig "$rig" -f "$frag" -r $ex/rules.yaml -O --emit spv -o "$out/$name.spv")
  l=$(cost --rig "$rig" -f "$frag" -r $ex/rules.yaml -O --emit spv -o "$out/$name-listed.spv" "${listed[@]}" 2>/dev/null || echo "-")
  local li="-"
  [ -f "$out/$name-listed.spv" ] && li=$(count "$out/$name-listed.spv")
  echo "| $name | $c | $(count "$out/$name.spv") | $l | $li |"
}

glslangValidator -V --target-env vulkan1.0 -o "$out/hand.spv" $ex/listing-3-3.vert >/dev/null
spirv-opt -O "$out/hand.spv" -o "$out/hand-opt.spv"

{
  echo "# Generated plans vs listing 3-3"
  echo
  echo "Regenerate with \`bash bench/compare_plans.sh\` (after building). Instruction counts are"
  echo "SPIR-V instructions (\`spirv-dis\` lines with an opcode) after \`spirv-opt -O\`; plan"
  echo "costs are in the rules' unit (vertex-program instruction slots, docs/cost-model.md)."
  echo
  echo "| example | chosen plan cost | chosen SPIR-V instr. | as-listed plan cost | as-listed SPIR-V instr. |"
  echo "|---|---|---|---|---|"
  row face $ex/face.rig.yaml $ex/face.frag
  row body $ex/body.rig.yaml $ex/face.frag
  row depth-only $ex/face.rig.yaml $ex/depth.frag
  echo
  echo "Hand port of listing 3-3 (\`examples/dawn/listing-3-3.vert\`, same interface as the face):"
  echo "**$(count "$out/hand-opt.spv")** SPIR-V instructions after \`spirv-opt -O\`; the generated face is"
  echo "**$(awk -v g="$(count "$out/face.spv")" -v h="$(count "$out/hand-opt.spv")" 'BEGIN { printf "%.2f", g / h }')** of it,"
  echo "with the degenerate-tangent fallback (issue 23 asks for at most 0.8)."
  echo
  echo "## What keeps the fallback cheap (issue 23)"
  echo
  echo "The fallback of \`object.tangent\` (docs/semantics.md) took the face from 0.81 to 0.89 of"
  echo "the hand port as an if/else. Three exact rewrites brought it to the figure above:"
  echo
  echo "- **A select instead of a branch** (the shared snippet \`tangent_orthonormal\`, rules/morph.yaml):"
  echo "  both candidates, then \`mix(b, normalize(g), bvec3(...))\`; Duff's \`s·a = −1/(1 + |N.z|)\`, so"
  echo "  the sign of N.z only picks the z component. 21 slots instead of 24; about 9 instructions"
  echo "  fewer than the if/else (no merge blocks, one select)."
  echo "- **The bone blend one column at a time** (\`bone_blend\`, rules/skinning.yaml): for each"
  echo "  column c, \`mat4(B0[c], B1[c], B2[c], B3[c]) * w\` is Σ w_k B_k[c], one matrix-vector product,"
  echo "  where a \`mat4\` sum is a column-wise add per influence in SPIR-V (16 instructions fewer)."
  echo "- **An attribute read in parts is loaded once** (the emitter): \`vec4(a_normal.xyz, a_normal.w)\`"
  echo "  was two loads and a rebuild per stream; from one local copy (\`vec4 vertex_normal_occlusion"
  echo "  = a_normal;\`) \`spirv-opt\` folds it back into the stream itself (the six normal/occlusion"
  echo "  streams: about 36 instructions)."
  echo
  echo "The frame rows are written as columns of \`transpose(mat3(T, B, N))\`, which the three"
  echo "rows share once optimised (6 instructions)."
  echo
  echo "## The choices that make the generated face smaller"
  echo
  echo "- **Blend the bone matrix once** (\`skin_matrix_blend\` + \`world_*_from_matrix\`) instead of"
  echo "  skinning position, normal and tangent separately per bone (listing 3-3): 16 + 3 + 6 + 6 = 31"
  echo "  slots against 16 + 19 + 19 = 54. Only worth it because three vectors share the matrix: the"
  echo "  depth-only pass, which needs the position alone, keeps the per-bone blend (16 < 16 + 3)."
  echo "- **N·V in world space** (\`ndotv_world_space\`) from \`WorldEyeDir\`, which the fragment shader"
  echo "  requests anyway, instead of the eye-space normal and eye vector of the listing (2 slots"
  echo "  against 3 + 5: the eye-space position is shared with the clip position either way)."
  echo "- **One dot product for the dapple term** (\`dapple_normal_z_row\`): only z of the rotated"
  echo "  normal is used."
  echo "- Kept from the listing because they are already cheapest: normal and occlusion morphed"
  echo "  together as one vec4 (\`normal_occlusion_morphed\`), Gram-Schmidt in object space, the"
  echo "  binormal from a cross product, the clip position from the eye-space position."
} > docs/comparison.md
cat docs/comparison.md
