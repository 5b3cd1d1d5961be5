#!/usr/bin/env bash
# Measures the largest GPU-vs-reference errors of `shadergen validate --cross-check` (every
# run: the chosen plan and every forced alternative) on the head, limb and Dawn-scale meshes,
# for the table in docs/validation.md.
#
#   bench/errors.sh [path/to/shadergen]     (default: build/generator/cli/shadergen)
#   POSES=8 bench/errors.sh ...             (poses per run; the Dawn-scale mesh uses 2)
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
sg="${1:-$here/build/generator/cli/shadergen}"
poses="${POSES:-8}"
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
d="$here/tests/validate/data"

run() {  # label mesh poses rig frag rules
  local label="$1" mesh="$2" np="$3"; shift 3
  local out
  if ! out="$("$sg" validate --rig "$1" -f "$2" -r "$3" --mesh "$mesh" --poses "$np" --cross-check 2>&1)"; then
    echo "$out" >&2
    echo "FAILED: $label" >&2
    exit 1
  fi
  # Output lines: "  ok   NAME  max abs A  max rel R  worst vertex ..."
  echo "$out" | awk -v label="$label" -v mesh="$mesh" -v np="$np" '
    /^device:/ { next }
    / plan cost / { runs++; split($0, a, ", "); split(a[2], b, " "); verts = b[1] }
    $1 == "ok" || $1 == "FAIL" {
      abs = $5 + 0; rel = $8 + 0
      if (abs > maxabs) { maxabs = abs; absat = $2 }
      if (rel > maxrel) { maxrel = rel; relat = $2 }
    }
    END { printf "| %s | %s | %s | %d | %d | %.3e (%s) | %.3e (%s) |\n", label, mesh, verts, np, runs, maxabs, absat, maxrel, relat }'
}

echo "| request | mesh | vertices | poses | runs | max abs error | max rel error |"
echo "|---|---|---|---|---|---|---|"
dawn=("$here/examples/dawn/face.rig.yaml" "$here/examples/dawn/face.frag" "$here/examples/dawn/rules.yaml")
std="$here/rules/standard.yaml"
run "Dawn face" head "$poses" "${dawn[@]}"
run "Dawn face" dawn 2 "${dawn[@]}"
run "limb2 (unorm16 weights)" limb "$poses" "$d/limb2.rig.yaml" "$d/world.frag" "$std"
run "limb8 (2 sets)" limb "$poses" "$d/limb8.rig.yaml" "$d/world.frag" "$std"
run "limb4 (unorm8 weights)" limb "$poses" "$d/limb4_unorm8.rig.yaml" "$d/world.frag" "$std"
run "rigid1" limb "$poses" "$d/rigid1.rig.yaml" "$d/eye.frag" "$std"
run "unskinned + model.matrix" limb "$poses" "$d/unskinned_model.rig.yaml" "$d/eye.frag" "$std"
run "unskinned + model.matrix" head "$poses" "$d/unskinned_model.rig.yaml" "$d/world.frag" "$std"
run "limb8 (2 sets)" head "$poses" "$d/limb8.rig.yaml" "$d/world.frag" "$std"
