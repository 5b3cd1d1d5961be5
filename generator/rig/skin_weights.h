// Skin weights that sum to one (docs/gltf.md#import-diagnostics-and-weights): the one
// renormalisation the glTF import (float weights, by default) and quantizeForRig (unorm codes
// that must sum to exactly 2^bits - 1, validate/program_inputs.cpp) share.
#pragma once
#include <cstddef>
#include <vector>

namespace sg {

// The validator's test (Khronos glTF-Validator, ACCESSOR_WEIGHTS_NON_NORMALIZED): the
// weights of one vertex, every set in order, summed in single precision, are normalized when
// the sum is within 2e-7 per non-zero weight of one.
bool skinWeightsNormalized(const float* w, size_t n);

// Renormalises one vertex's weights (every set in order) in place, as three.js's
// SkinnedMesh.normalizeSkinWeights does: each divided by the sum of their magnitudes, and
// all-zero weights become the first influence alone (1, 0, 0, ...). With steps > 0 (a unorm
// format, 2^bits - 1) the results are codes / steps whose codes sum to exactly `steps`:
// each the floor of w / sum in steps, the remainder given one step at a time to the largest
// fractions (first on ties), as gltfpack rounds them.
void normalizeSkinWeights(double* w, size_t n, double steps = 0);

}  // namespace sg
