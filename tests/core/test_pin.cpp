// Pins (pipeline/pin.h): the file bench --pin-out writes and generate --pin reads, and pin merge's
// choice over several devices, checked against regrets worked out by hand.
#include <gtest/gtest.h>

#include <string>

#include "pipeline/pin.h"

namespace {

const std::string kInputs = std::string(64, 'a');

sg::Pin devicePin(const std::string& device, const std::vector<std::pair<std::string, double>>& plans,
                  const std::string& inputs = kInputs) {
  sg::Pin p;
  p.file = device + ".pin.yaml";
  p.inputs = inputs;
  for (const auto& [name, ns] : plans)
    p.timed.push_back({"plan " + name, "program-" + name, {"rule_" + name, "shared"}, {"other_" + name}, ns});
  const sg::TimedPlan* fastest = &p.timed[0];
  for (const auto& t : p.timed)
    if (t.nsPerVertex < fastest->nsPerVertex) fastest = &t;
  p.devices = {{device, device + " driver", "timestamps", fastest->nsPerVertex, fastest->nsPerVertex, p.timed[0].nsPerVertex}};
  p.label = fastest->label, p.program = fastest->program, p.rules = fastest->rules, p.bans = fastest->bans;
  p.candidates = p.timed.size();
  // As read from a file: errors point into it.
  return sg::parsePin(sg::formatPin(p), p.file);
}

TEST(Pin, MergeTakesThePlanWhoseWorstRegretIsLeast) {
  // A times x, y, z at 1.0, 1.1, 1.3; B at 2.0, 1.5, 1.5 and w, which A did not time, at 1.2. Each
  // regret is over the device's own fastest (A 1.0, B 1.2): x max(1, 2/1.2 = 1.667), y max(1.1,
  // 1.5/1.2 = 1.25), z max(1.3, 1.25). y's 1.25 is least, though neither device times it fastest.
  const sg::Pin a = devicePin("A", {{"x", 1.0}, {"y", 1.1}, {"z", 1.3}});
  const sg::Pin b = devicePin("B", {{"x", 2.0}, {"w", 1.2}, {"y", 1.5}, {"z", 1.5}});
  const sg::Pin m = sg::mergePins({a, b});
  EXPECT_EQ(m.label, "plan y");
  EXPECT_EQ(m.program, "program-y");
  EXPECT_EQ(m.rules, (std::vector<std::string>{"rule_y", "shared"}));
  EXPECT_EQ(m.bans, std::vector<std::string>{"other_y"});
  EXPECT_EQ(m.inputs, kInputs);
  EXPECT_EQ(m.candidates, 3u);  // timed on both
  ASSERT_EQ(m.devices.size(), 2u);
  EXPECT_EQ(m.devices[0].device, "A");
  EXPECT_DOUBLE_EQ(m.devices[0].nsPerVertex, 1.1);
  EXPECT_DOUBLE_EQ(m.devices[0].fastestNsPerVertex, 1.0);
  EXPECT_DOUBLE_EQ(m.devices[0].generatedNsPerVertex, 1.0);
  EXPECT_EQ(m.devices[1].device, "B");
  EXPECT_DOUBLE_EQ(m.devices[1].nsPerVertex, 1.5);
  EXPECT_DOUBLE_EQ(m.devices[1].fastestNsPerVertex, 1.2);
  EXPECT_DOUBLE_EQ(m.devices[1].generatedNsPerVertex, 2.0);
  EXPECT_EQ(m.deviceNames(), "A + B");
  // The order of the pins names the devices' order, not the choice.
  EXPECT_EQ(sg::mergePins({b, a}).label, "plan y");
  // Written and read back: the same pin, its devices included; a merged pin carries no timed plans.
  const sg::Pin back = sg::parsePin(sg::formatPin(m), "m.pin.yaml");
  EXPECT_EQ(back.devices, m.devices);
  EXPECT_EQ(back.rules, m.rules);
  EXPECT_EQ(back.bans, m.bans);
  EXPECT_EQ(back.candidates, 3u);
  EXPECT_TRUE(back.timed.empty());
  // A third device where y is 2x its fastest moves the choice to z (A 1.3, B 1.25, C 1.0 worst 1.3)
  // rather than x (C 1.0 but B 1.667).
  const sg::Pin c = devicePin("C", {{"x", 1.0}, {"y", 2.0}, {"z", 1.0}});
  EXPECT_EQ(sg::mergePins({a, b, c}).label, "plan z");
}

TEST(Pin, MergeBreaksTiesInTheFirstPinsOrder) {
  // x and y both at worst 1.5: the first pin lists y first (its objective's order), so y.
  const sg::Pin a = devicePin("A", {{"y", 1.5}, {"x", 1.0}});
  const sg::Pin b = devicePin("B", {{"x", 1.5}, {"y", 1.0}});
  EXPECT_EQ(sg::mergePins({a, b}).label, "plan y");
  EXPECT_EQ(sg::mergePins({b, a}).label, "plan x");
}

TEST(Pin, MergeRefusesPinsItCannotWeigh) {
  const sg::Pin a = devicePin("A", {{"x", 1.0}, {"y", 1.1}});
  auto error = [](const std::vector<sg::Pin>& pins) {
    try {
      sg::mergePins(pins);
    } catch (const sg::InputError& e) {
      return sg::formatDiagnostic(e.diagnostic());
    }
    return std::string("no error");
  };
  // Other inputs: the second pin's inputs line.
  EXPECT_NE(error({a, devicePin("B", {{"x", 1.0}}, std::string(64, 'b'))})
                .find("B.pin.yaml:13:9: error: pin merge: measured with other inputs' bytes than A.pin.yaml"),
            std::string::npos);
  // No plan timed on both: the same rules but another program is another plan.
  sg::Pin other = devicePin("B", {{"x", 1.0}});
  other.timed[0].program = "program-elsewhere";
  EXPECT_NE(error({a, other}).find("A.pin.yaml:3:1: error: pin merge: no plan was timed on every device (2 plans here"),
            std::string::npos);
  // A pin of before session 41: no timed plans.
  const sg::Pin old = sg::parsePin(
      "device: \"NVIDIA H100 80GB HBM3\"\ndriver: \"NVIDIA 580.159.04\"\nclock: \"raster on, timestamps\"\ncandidates: 4\n"
      "plan: \"generated\"\nprogram: \"0fde580a175d9784\"\nns_per_vertex: 1.3184222222222222\n"
      "generated_ns_per_vertex: 1.3184222222222222\nrules: [\"clip_from_eye\"]\nban: [\"clip_from_view_projection\"]\ninputs: " +
          kInputs + "\n",
      "old.pin.yaml");
  EXPECT_TRUE(old.timed.empty());
  ASSERT_EQ(old.devices.size(), 1u);
  EXPECT_DOUBLE_EQ(old.devices[0].fastestNsPerVertex, 1.3184222222222222);
  EXPECT_NE(error({a, old}).find("old.pin.yaml:1:1: error: pin merge: the pin lists no timed plans"), std::string::npos);
  // A merged pin, and a single pin.
  const sg::Pin merged = sg::mergePins({a, devicePin("B", {{"x", 1.0}})});
  EXPECT_NE(error({merged, a}).find("error: pin merge: a merged pin is not merged again"), std::string::npos);
  EXPECT_NE(error({a}).find("error: pin merge: weighs two pins at least"), std::string::npos);
}

TEST(Pin, AMalformedMergedPinIsALocatedError) {
  const sg::Pin m = sg::mergePins({devicePin("A", {{"x", 1.0}, {"y", 1.1}}), devicePin("B", {{"x", 2.0}, {"y", 1.5}})});
  const std::string text = sg::formatPin(m);
  auto error = [](const std::string& t) {
    try {
      sg::parsePin(t, "m.pin.yaml");
    } catch (const sg::InputError& e) {
      return sg::formatDiagnostic(e.diagnostic());
    }
    return std::string("no error");
  };
  // One device only.
  const size_t second = text.find("  - device: \"B\"");
  ASSERT_NE(second, std::string::npos);
  const size_t after = text.find("candidates:");
  EXPECT_NE(error(text.substr(0, second) + text.substr(after)).find("error: devices: a merged pin weighs two devices at least"),
            std::string::npos);
  // A device's fastest slower than the pinned plan there.
  std::string slower = text;
  slower.replace(slower.find("fastest_ns_per_vertex: 1\n"), 25, "fastest_ns_per_vertex: 9\n");
  EXPECT_NE(error(slower).find("error: fastest_ns_per_vertex: more than the pinned plan's ns_per_vertex"), std::string::npos);
  // A single device's keys beside `devices`.
  EXPECT_NE(error("device: \"A\"\n" + text).find("unknown key 'device'"), std::string::npos) << error("device: \"A\"\n" + text);
}

}  // namespace
