// Device calibration (shadergen calibrate, docs/device-profiles.md): measures what a device
// pays per vertex for each term of the cost model and fits a device profile.
//
// Probes are small vertex programs that vary one term at a time over the vertices and
// triangles of a procedural mesh: vertex input locations at fixed bytes, bytes at fixed
// locations, the length of a dependent arithmetic chain, storage-buffer loads, uniform
// palette loads indexed per vertex (against the same loads at a uniform index), and output
// components. Every probe is first run with its outputs captured and compared with the
// values it must compute (computed here on the CPU from the same data); only a probe that
// agrees is timed. Generated plans (the rig's plan and its forced alternatives, bench's
// rows) join the probes as samples. The weights are the non-negative least-squares fit
// (common/nnls.h) of ns per vertex on the terms' amounts, relative errors weighted equally.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "render/gpu_bench.h"
#include "search/device_profile.h"

namespace sg {

struct CalibrationOptions {
  std::string device;               // "" = lavapipe
  bool validationLayers = true;
  std::vector<std::string> meshes{"dawn", "head"};  // the first one's samples give the weights
  uint32_t drawsPerFrame = 16;
  uint32_t frames = 9;              // + 1 warm-up frame
  uint32_t rounds = 2;              // best round counts
  bool probes = true;
  // The generated plan and every forced alternative of this generation (bench's programs),
  // when gen.rigPath is set.
  GenerateOptions plans;
};

struct CalibrationSample {
  std::string label;  // "locations 8 (float32x4)", "plan: generated", ...
  std::string mesh;
  TermAmounts amounts{};
  bool validated = false;
  std::string failure;      // why it was not timed (its outputs disagreed, or it did not run)
  double measuredNs = -1;   // per vertex, raster on, timestamps
  double predictedNs = -1;  // under the fitted profile
};

struct CalibrationFit {
  std::string mesh;
  size_t samples = 0;
  double rmsRelativeError = 0, maxRelativeError = 0;
  double spearman = 0;  // predicted against measured
};

struct CalibrationReport {
  std::string device, driver;
  std::string clock;  // what measured the samples: GPU timestamps, or host time on a CPU device
  std::vector<CalibrationSample> samples;
  DeviceProfile profile;
  std::vector<CalibrationFit> fits;  // one per mesh, under the profile fitted on the first
};

CalibrationReport calibrateDevice(const CalibrationOptions& opts);

// The fit alone (exposed for tests): weights >= 0 minimising the relative error of
// predicted against measured ns per vertex over the validated samples of `mesh`.
DeviceProfile fitDeviceProfile(const std::vector<CalibrationSample>& samples, const std::string& mesh,
                               const std::string& deviceName);
// Fills predictedNs of every sample and the fit statistics per mesh.
std::vector<CalibrationFit> evaluateFit(std::vector<CalibrationSample>& samples, const DeviceProfile& profile,
                                        const std::vector<std::string>& meshes);

// The report as text (samples table, weights, fit errors), and the profile as a documented
// YAML file that loadDeviceProfile reads back.
std::string formatCalibration(const CalibrationReport& report);
std::string deviceProfileYaml(const CalibrationReport& report);

}  // namespace sg
