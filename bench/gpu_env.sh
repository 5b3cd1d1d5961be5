# Sourced by gpu_run.sh and gpu_calibrate.sh inside the unpacked bundle ($here): the bundle's
# libraries, a Vulkan runtime dir, the CLI ($sg), the Dawn face's arguments ($dawn), the rigs and
# models first timed after the profiles were fitted ($unseenRigs, $unseenModels: gpu_collect.sh
# times them, gpu_verify.sh SG_VERIFY_SET=unseen times the profile's choices), and the GPU and
# driver printed first.
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp/shadergen-xdg}
mkdir -p "$XDG_RUNTIME_DIR" && chmod 700 "$XDG_RUNTIME_DIR"
sg="$here/bin/shadergen"
dawn=(--rig "$here/examples/dawn/face.rig.yaml" -f "$here/examples/dawn/face.frag" -r "$here/examples/dawn/rules.yaml"
      --templates "$here/templates")
unseenRigs=(limb8 limb4_unorm8 face52_sparse octahedral_or_float qtangent_or_float morph_scaled bitpacked_or_separate threejs-mesh)
unseenModels=(LeePerrySmith.glb AnimatedMorphSphere.meshopt-cc-kv.glb MorphStressTest.gltf)
command -v nvidia-smi > /dev/null && nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
