// Fitting a device profile to timings (docs/device-profiles.md, "Calibration"): the weights
// >= 0 that minimise the weighted relative error of predicted against measured ns per vertex,
// solved by Ceres Solver (bounded nonlinear least squares). Two forms of model:
//   additive  ns = sum_t (w_t + d_t / V) x_t                      (every profile before issue 33)
//   roofline  ns = sum_t (w_t + d_t / V) x_t  +  max_p sum_{t in p} w_pt x_t
//   raster    the roofline without per-draw weights, its additive part the fixed cost per vertex,
//             one per fragment the draw covers (x_fragments scaled by fragments per vertex) and
//             the share of input locations and storage-buffer loads outside the overlap
//             (FitOptions::outsidePipes)
// where x_t is the amount of term t, scaled by a workload feature where the form says so
// (uniform loads at a per-vertex index, elements and vec4s, by the joints a warp reads), and
// V the vertices per draw. In the roofline form the additive part holds the per-vertex fixed
// cost and the per-draw weights; the pipes hold the rest (fetch: locations and attribute bytes;
// memory: storage-buffer loads; constant: uniform loads at a per-vertex index; alu: arithmetic;
// output: outputs), which the device overlaps. The raster form prices what the per-draw weights
// stood in for on the H200 (docs/device-profiles.md, "The rasterizer's share"): the fragments a
// draw covers, counted by the device. Any form may add hinges max(0, x_t - at) x w_h on terms
// asked for (FitOptions::thresholds), each `at` chosen on a grid of the rows' amounts.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "search/device_profile.h"
#include "search/workload.h"

namespace sg {

struct FitRow {
  TermAmounts amounts{};
  double vertices = 0;  // per draw
  Workload workload;    // of the mesh it was timed on
  double measuredNs = 0;
  double weight = 1;  // of its squared relative error
};

enum class ProfileForm { Additive, Roofline, Raster };
const char* profileFormName(ProfileForm form);  // "additive", "roofline", "raster"

// What a fit fits: the form, and the optional terms below (the constant cache and draw sizes
// kept only where they lower the error; the pipes' sum share whenever asked).
struct FitOptions {
  ProfileForm form = ProfileForm::Additive;
  bool constantCache = false;  // roofline and raster forms
  bool drawSizes = false;      // raster form
  bool pipeSumShare = false;   // roofline and raster forms
  // Roofline and raster forms: the terms priced in the additive part as well as in their pipe,
  // the share of their cost the device does not overlap with the other pipes. Unset: the
  // form's own (outsidePipesOf).
  std::optional<std::vector<int>> outsidePipes;
  // Terms that may cost more per unit past a threshold (DeviceProfile::thresholds), each tried
  // at every threshold the rows part (kMinRowsPerSideOfThreshold) and kept where it lowers the
  // error by kMinTermGain. Lavapipe: `locations` (docs/device-profiles.md, "A price past a threshold").
  std::vector<int> thresholds;
  // Whether bench's floors are rows of the fit (fitDeviceProfile). Their inputs are read and summed
  // at once; where a device prices an input by the shader around it (lavapipe past 15 inputs), a
  // floor prices inputs as no plan pays them.
  bool floors = true;
  FitOptions() = default;
  FitOptions(ProfileForm f, bool cache = false, bool sizes = false, bool share = false)
      : form(f), constantCache(cache), drawSizes(sizes), pipeSumShare(share) {}
};

// The terms a form prices outside its pipes as well as in them (FitOptions::outsidePipes unset).
// The raster form: a vertex's input locations and its storage-buffer loads (and their vec4s).
// Fitted so on the H200's and the H100's training logs, they came out at about a quarter of a
// location's price (0.12-0.16 ns against 0.32-0.36 in the fetch pipe) and most of a vec4 load's,
// and the profiles chose and ranked held-out plans better than with every term inside its pipe
// (docs/device-profiles.md, "Inputs outside the overlap"). The roofline form: none.
std::vector<int> outsidePipesOf(ProfileForm form);

struct FitResult {
  DeviceProfile profile;       // device and file left empty
  double rmsRelativeError = 0;  // over the rows, unweighted
  double maxRelativeError = 0;
  bool converged = false;
};

// The constant cache (`constantCache`, roofline and raster forms): where rows that read a uniform at a per-vertex
// index have palette footprints (Workload::paletteEntriesPerWarp) on both sides of a threshold
// C, kMinRowsPerSideOfCapacity rows at least on each, the fit tries each C between two such
// footprints with a miss factor M >= 1 as one more parameter (a row past C pays M times its
// terms scaled by joints per warp), and keeps the best C where it lowers the weighted squared
// error by kMinTermGain of the fit without it; else the profile has no constant_cache.
constexpr size_t kMinRowsPerSideOfCapacity = 3;
// A threshold (FitOptions::thresholds) is tried between two distinct amounts of its term with at
// least this many rows on each side, at the lower amount (rows at or below it pay nothing more).
constexpr size_t kMinRowsPerSideOfThreshold = 3;
// The pipes' sum share (`pipeSumShare`, roofline and raster forms; DeviceProfile::pipeSumShare):
// one more parameter s in [0, 1], a row costing additive + (1 - s) x slowest pipe + s x every
// pipe; fitted whenever asked (a share below kLeastPipeSumShare is written as none), before
// draw sizes and the constant cache, which then keep it.
constexpr double kLeastPipeSumShare = 0.001;
constexpr double kMinTermGain = 0.02;  // of the weighted squared error, for a term to be kept
// A relative error per row below which a fit counts as exact (no term can lower it further).
constexpr double kNegligibleRelativeError = 1e-6;

// Per-draw weights only when the rows' draws differ in size (else they cannot be told apart
// from per-vertex ones). Deterministic: same rows, same weights. Throws std::runtime_error
// without rows.
//
// Draw sizes (`drawSizes`, raster form; docs/device-profiles.md, "Draw sizes"): where the rows
// hold kMinRowsPerDrawSize rows at each of two vertex counts per draw or more, one set of
// weights per such size, a row between two sizes priced by their weights interpolated in
// log(vertices) as the profile prices it (DeviceProfile::atDrawSize); kept where it lowers the
// weighted squared error by kMinTermGain. A fragment's price and the constant cache's miss factor
// are shared by every size.
constexpr size_t kMinRowsPerDrawSize = 24;
FitResult fitProfile(const std::vector<FitRow>& rows, const FitOptions& options);

// The upper median (of an even count, the larger middle value); 0 when empty.
double medianOf(std::vector<double> v);

// The form's skeleton: pipes (empty for additive) and the workload scaling, weights zero.
DeviceProfile profileForm(ProfileForm form);

}  // namespace sg
