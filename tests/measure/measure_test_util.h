// Shared by the measuring tests: the quickest calibration lavapipe can run.
#pragma once
#include "measure/calibrate.h"

namespace sg::testing {

// One small mesh, one draw a frame, one frame, one round: every sample is timed once (no timing
// is asserted; what is checked is which samples exist, validate and carry which amounts).
inline CalibrationOptions quickCalibration() {
  CalibrationOptions o;
  o.meshes = {"small"};
  o.drawsPerFrame = 1;
  o.minVerticesPerFrame = 0;
  o.frames = 1;
  o.rounds = 1;
  return o;
}

}  // namespace sg::testing
