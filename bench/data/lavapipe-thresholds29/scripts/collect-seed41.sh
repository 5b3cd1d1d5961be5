#!/usr/bin/env bash
# collect-seed41.sh OUTDIR (session 29): rigs no lavapipe log had timed, chosen for their many inputs: of the 80
# random rigs of corpus seed 41, the six whose instruction-slot plan reads 12 or more input locations
# (corpus-158244986 and -1977102515: 16; -2593583386 and -3003821061: 13; -2506568852 and -3581741254: 12).
# Each timed on lavapipe as session 17's training group was (4 draws, 3 frames, 6 rounds, both meshes), its
# instruction-slot plan, the forced alternatives and the floors, and the plan of each profile given (--plans-under)
# with its alternatives, every program validated first; one log per rig.
#   Usage: bash collect-seed41.sh OUTDIR PROFILE...
set -euo pipefail
cd "$(git -C "$(dirname "$0")" rev-parse --show-toplevel)"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/xdg}
out=$1; shift; mkdir -p "$out"
under=(); for p in "$@"; do under+=(--plans-under "$p"); done
corpus=$(mktemp -d); trap 'rm -rf "$corpus"' EXIT
sg=build/generator/cli/shadergen
$sg calibrate --corpus 80 --seed 41 --write-corpus "$corpus" -r examples/dawn/rules.yaml > /dev/null
for r in corpus-158244986 corpus-1977102515 corpus-2593583386 corpus-3003821061 corpus-2506568852 corpus-3581741254; do
  /usr/bin/time -f "$r: %e s" $sg calibrate --rig "$corpus/$r.rig.yaml" -f "$corpus/$r.frag" -r examples/dawn/rules.yaml \
    --templates templates --no-probes --no-check --no-validation-layers --meshes dawn,head --draws 4 --frames 3 --rounds 6 \
    "${under[@]}" > "$out/$r.log"
done
