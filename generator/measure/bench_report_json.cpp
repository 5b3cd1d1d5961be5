#include "measure/bench_report_json.h"

#include <cmath>
#include <optional>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace sg {
namespace {

using nlohmann::json;

// JSON has no NaN: null stands for it (a ratio or correlation not taken).
json number(double x) { return std::isnan(x) ? json(nullptr) : json(x); }
double number(const json& j) { return j.is_null() ? NAN : j.get<double>(); }

json spreadJson(const RoundSpread& s) { return {{"least", number(s.least)}, {"most", number(s.most)}, {"rounds", s.rounds}}; }
RoundSpread spreadFrom(const json& j) { return {number(j.at("least")), number(j.at("most")), j.at("rounds").get<size_t>()}; }

json workloadJson(const Workload& w) {
  return {{"vertices_per_draw", w.verticesPerDraw},         {"joints_per_warp", w.jointsPerWarp},
          {"active_morph_targets", w.activeMorphTargets},   {"invocations_per_vertex", w.invocationsPerVertex},
          {"source", w.source},                             {"fragments_per_vertex", w.fragmentsPerVertex},
          {"palette_entries_per_warp", w.paletteEntriesPerWarp}};
}
Workload workloadFrom(const json& j) {
  Workload w;
  w.verticesPerDraw = j.at("vertices_per_draw");
  w.jointsPerWarp = j.at("joints_per_warp");
  w.activeMorphTargets = j.at("active_morph_targets");
  w.invocationsPerVertex = j.at("invocations_per_vertex");
  w.source = j.at("source");
  w.fragmentsPerVertex = j.at("fragments_per_vertex");
  w.paletteEntriesPerWarp = j.at("palette_entries_per_warp");
  return w;
}

json rowJson(const GpuBenchRow& r) {
  json statistics = json::array();
  for (const auto& st : r.driverStatistics) statistics.push_back({{"executable", st.executable}, {"name", st.name}, {"value", st.value}});
  return {{"label", r.label},
          {"rules", r.rules},
          {"bans", r.bans},
          {"pin", r.pin},
          {"has_cost", r.hasCost},
          {"has_amounts", r.hasAmounts},
          {"plan_cost", r.planCost},
          {"spirv_instructions", r.spirvInstructions},
          {"program", r.program},
          {"validation", r.validation},
          {"amounts", r.amounts},
          {"predicted", r.predictedNsPerVertex},
          {"raster_on", r.rasterOnNsPerVertex},
          {"raster_off", r.rasterOffNsPerVertex},
          {"raster_on_wall", r.rasterOnWallNsPerVertex},
          {"raster_off_cpu", r.rasterOffCpuNsPerVertex},
          {"raster_off_wall", r.rasterOffWallNsPerVertex},
          {"rounds", r.roundNsPerVertex},
          {"driver_statistics", statistics}};
}
GpuBenchRow rowFrom(const json& j) {
  GpuBenchRow r;
  r.label = j.at("label");
  r.rules = j.at("rules").get<std::vector<std::string>>();
  r.bans = j.at("bans").get<std::vector<std::string>>();
  r.pin = j.at("pin").get<std::vector<std::string>>();
  r.hasCost = j.at("has_cost");
  r.hasAmounts = j.at("has_amounts");
  r.planCost = j.at("plan_cost");
  r.spirvInstructions = j.at("spirv_instructions");
  r.program = j.at("program");
  r.validation = j.at("validation");
  r.amounts = j.at("amounts").get<TermAmounts>();
  r.predictedNsPerVertex = j.at("predicted");
  r.rasterOnNsPerVertex = j.at("raster_on");
  r.rasterOffNsPerVertex = j.at("raster_off");
  r.rasterOnWallNsPerVertex = j.at("raster_on_wall");
  r.rasterOffCpuNsPerVertex = j.at("raster_off_cpu");
  r.rasterOffWallNsPerVertex = j.at("raster_off_wall");
  r.roundNsPerVertex = j.at("rounds").get<std::vector<double>>();
  for (const auto& st : j.value("driver_statistics", json::array()))
    r.driverStatistics.push_back({st.at("executable"), st.at("name"), st.at("value")});
  return r;
}

json noteJson(const Diagnostic& d) {
  return {{"severity", int(d.severity)}, {"file", d.loc.file}, {"line", d.loc.line}, {"col", d.loc.col}, {"message", d.message}, {"code", d.code}};
}
Diagnostic noteFrom(const json& j) {
  const int s = j.at("severity");
  if (s < int(Severity::Error) || s > int(Severity::Note)) throw std::runtime_error("bench report: unknown severity");
  return {Severity(s), {j.at("file"), j.at("line"), j.at("col")}, j.at("message"), j.at("code")};
}

}  // namespace

std::string benchReportJson(const GpuBenchReport& r) {
  json rows = json::array(), notes = json::array();
  for (const auto& row : r.rows) rows.push_back(rowJson(row));
  for (const auto& n : r.notes) notes.push_back(noteJson(n));
  const json j = {{"device", r.device},
                  {"driver", r.driver},
                  {"limits", r.limits},
                  {"vertices", r.vertices},
                  {"triangles", r.triangles},
                  {"workload", workloadJson(r.workload)},
                  {"shaded_vertices_per_vertex", r.shadedVerticesPerVertex},
                  {"draws_per_frame", r.drawsPerFrame},
                  {"frames", r.frames},
                  {"rounds", r.rounds},
                  {"processes", r.processes},
                  {"width", r.width},
                  {"height", r.height},
                  {"rows", rows},
                  {"pearson_on", number(r.pearsonOn)},
                  {"spearman_on", number(r.spearmanOn)},
                  {"pearson_off", number(r.pearsonOff)},
                  {"spearman_off", number(r.spearmanOff)},
                  {"pearson_off_wall", number(r.pearsonOffWall)},
                  {"spearman_off_wall", number(r.spearmanOffWall)},
                  {"spearman_predicted_on", number(r.spearmanPredictedOn)},
                  {"generated_over_fastest_on", number(r.generatedOverFastestOn)},
                  {"by_round", spreadJson(r.byRound)},
                  {"prediction_clock", r.predictionClock},
                  {"input_memory", r.inputMemory},
                  {"fastest_plan", r.fastestPlan},
                  {"fastest_over_generated", number(r.fastestOverGenerated)},
                  {"notes", notes},
                  {"inputs", r.inputs}};
  return j.dump();
}

std::string inputErrorJson(const InputError& e) {
  json related = json::array();
  for (const auto& d : e.related) related.push_back(noteJson(d));
  return json{{"input_error", noteJson(e.diagnostic())}, {"related", related}}.dump();
}

GpuBenchReport benchReportFromJson(const std::string& text) {
  json j;
  std::optional<InputError> error;
  try {
    j = json::parse(text);
    if (j.contains("input_error")) {
      error.emplace(noteFrom(j.at("input_error")));
      for (const auto& d : j.at("related")) error->related.push_back(noteFrom(d));
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("bench report: not a report this shadergen writes: ") + e.what());
  }
  if (error) throw *error;
  try {
    GpuBenchReport r;
    r.device = j.at("device");
    r.driver = j.at("driver");
    r.limits = j.at("limits");
    r.vertices = j.at("vertices");
    r.triangles = j.at("triangles");
    r.workload = workloadFrom(j.at("workload"));
    r.shadedVerticesPerVertex = j.at("shaded_vertices_per_vertex");
    r.drawsPerFrame = j.at("draws_per_frame");
    r.frames = j.at("frames");
    r.rounds = j.at("rounds");
    r.processes = j.at("processes");
    r.width = j.at("width");
    r.height = j.at("height");
    for (const auto& row : j.at("rows")) r.rows.push_back(rowFrom(row));
    r.pearsonOn = number(j.at("pearson_on"));
    r.spearmanOn = number(j.at("spearman_on"));
    r.pearsonOff = number(j.at("pearson_off"));
    r.spearmanOff = number(j.at("spearman_off"));
    r.pearsonOffWall = number(j.at("pearson_off_wall"));
    r.spearmanOffWall = number(j.at("spearman_off_wall"));
    r.spearmanPredictedOn = number(j.at("spearman_predicted_on"));
    r.generatedOverFastestOn = number(j.at("generated_over_fastest_on"));
    r.byRound = spreadFrom(j.at("by_round"));
    r.predictionClock = j.at("prediction_clock");
    r.inputMemory = j.at("input_memory");
    r.fastestPlan = j.at("fastest_plan");
    r.fastestOverGenerated = number(j.at("fastest_over_generated"));
    for (const auto& n : j.at("notes")) r.notes.push_back(noteFrom(n));
    r.inputs = j.at("inputs");
    return r;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(std::string("bench report: not a report this shadergen writes: ") + e.what());
  }
}

}  // namespace sg
