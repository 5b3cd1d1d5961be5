// `shadergen explain` on the Dawn face: the structure of the tree and table, and its
// numbers checked independently (the total against `generate`, each alternative against
// a separate search with the rule banned); and the report for an impossible request.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "analysis/explain.h"
#include "analysis_test_util.h"
#include "pipeline/generate.h"

namespace sg {
namespace {

using sg::testing::runCli;
using sg::testing::sourceDir;

std::string dawn(const char* f) { return sourceDir() + "/examples/dawn/" + f; }

GenerateOptions dawnOptions() {
  GenerateOptions o;
  o.rigPath = dawn("face.rig.yaml");
  o.fragmentPath = dawn("face.frag");
  o.rulesPaths = {dawn("rules.yaml")};
  return o;
}

struct Row {
  int64_t cost = 0;
  int uses = 0;
  bool alternative = false;
  int64_t altTotal = 0;
  int64_t extra = 0;
};

struct Parsed {
  int64_t headerTotal = -1, footerTotal = -1;
  int headerRules = -1;
  std::map<std::string, Row> rows;                // the choices table
  std::map<std::string, int64_t> treeCost;        // "<- rule (cost N" lines of the tree
  std::map<std::string, int> treeCount;           // how often each rule appears in the tree
  std::vector<std::string> roots;                 // output lines
  std::set<std::string> sharedMarked;             // facts marked shared in the tree
  int sharedRefs = 0;                             // "(shared: computed above, paid once)" lines
};

Parsed parse(const std::string& out) {
  Parsed p;
  static const std::regex header(R"(^plan for rig '([^']+)' and fragment shader '([^']+)': (\d+) rules, total cost (\d+)$)");
  static const std::regex node(R"(^\s+(\S+) <- (\S+) \(cost (\d+)(, shared by (\d+) uses, paid once)?\)  \[without it: (.*)\]$)");
  static const std::regex ref(R"(^\s+(\S+)  \(shared: computed above, paid once\)$)");
  static const std::regex root(R"(^(\S+) \((\w+) (location \d+|position)\) = (.+)$)");
  static const std::regex row(R"(^  (\S+)\s+(\S+)\s+(\d+)\s+(\d+)  (no alternative|total (\d+) \(\+(\d+)\)( using .*)?)$)");
  static const std::regex footer(R"(^total cost (\d+) \((\d+) rules, each paid once; \w+ A\*\)$)");
  std::istringstream in(out);
  bool table = false;
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_match(line, m, header)) {
      p.headerRules = std::stoi(m[3]);
      p.headerTotal = std::stoll(m[4]);
    } else if (line.rfind("choices and their cheapest alternatives", 0) == 0) {
      table = true;
    } else if (std::regex_match(line, m, footer)) {
      p.footerTotal = std::stoll(m[1]);
    } else if (table && std::regex_match(line, m, row)) {
      if (m[1] == "rule") continue;
      Row r;
      r.cost = std::stoll(m[3]);
      r.uses = std::stoi(m[4]);
      r.alternative = m[5] != "no alternative";
      if (r.alternative) {
        r.altTotal = std::stoll(m[6]);
        r.extra = std::stoll(m[7]);
      }
      p.rows[m[1]] = r;
    } else if (!table && std::regex_match(line, m, node)) {
      p.treeCost[m[2]] = std::stoll(m[3]);
      p.treeCount[m[2]]++;
      if (m[4].matched) p.sharedMarked.insert(m[1]);
    } else if (!table && std::regex_match(line, m, ref)) {
      p.sharedRefs++;
    } else if (!table && std::regex_match(line, m, root)) {
      p.roots.push_back(m[1]);
    }
  }
  return p;
}

class DawnExplain : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto o = dawnOptions();
    cli_ = new sg::testing::CliResult(runCli({"explain", "--rig", o.rigPath, "-f", o.fragmentPath, "-r", o.rulesPaths[0]}));
    parsed_ = new Parsed(parse(cli_->output));
  }
  static void TearDownTestSuite() {
    delete cli_;
    delete parsed_;
  }
  static sg::testing::CliResult* cli_;
  static Parsed* parsed_;
};
sg::testing::CliResult* DawnExplain::cli_ = nullptr;
Parsed* DawnExplain::parsed_ = nullptr;

TEST_F(DawnExplain, Structure) {
  ASSERT_EQ(cli_->status, 0) << cli_->output;
  const Parsed& p = *parsed_;
  // Every output of the Dawn interface is a root, gl_Position first.
  std::vector<std::string> roots{"gl_Position",     "WorldTanMatrixX", "WorldTanMatrixY", "WorldTanMatrixZ",
                                 "WorldEyeDir",     "SkinUVST",        "SkinSilhouetteVec"};
  EXPECT_EQ(p.roots, roots) << cli_->output;
  // Every chosen rule appears once in the tree (shared values are referenced, not repeated)
  // with the cost the table states.
  ASSERT_EQ(static_cast<int>(p.rows.size()), p.headerRules) << cli_->output;
  for (const auto& [rule, r] : p.rows) {
    EXPECT_EQ(p.treeCount.count(rule) ? p.treeCount.at(rule) : 0, 1) << rule;
    EXPECT_EQ(p.treeCost.count(rule) ? p.treeCost.at(rule) : -1, r.cost) << rule;
  }
  // The world normal feeds the three frame rows, the binormal, N.V and the dapple term.
  EXPECT_TRUE(p.sharedMarked.count("world.normal")) << cli_->output;
  EXPECT_NE(cli_->output.find("world.normal <- world_normal_from_matrix (cost 6, shared by 6 uses, paid once)"),
            std::string::npos)
      << cli_->output;
  EXPECT_TRUE(p.sharedMarked.count("skin.matrix"));
  EXPECT_GT(p.sharedRefs, 0);
  // Rig inputs are listed under the rule that reads them, morph targets compacted.
  EXPECT_NE(cli_->output.find("from the rig: vertex.position, morph.position[0..4], morph.weights"), std::string::npos)
      << cli_->output;
}

TEST_F(DawnExplain, TotalMatchesGenerate) {
  const Parsed& p = *parsed_;
  GenerateResult g = generate(dawnOptions());
  EXPECT_EQ(p.headerTotal, g.plan.cost);
  EXPECT_EQ(p.footerTotal, g.plan.cost);
  EXPECT_EQ(p.headerRules, static_cast<int>(g.plan.actions.size()));
  int64_t sum = 0;
  for (const auto& [rule, r] : p.rows) sum += r.cost;
  EXPECT_EQ(sum, g.plan.cost) << "each rule paid once";
  // And against the CLI's own generate output.
  auto o = dawnOptions();
  auto dir = sg::testing::scratchDir("explain_generate");
  auto gen = runCli({"generate", "--rig", o.rigPath, "-f", o.fragmentPath, "-r", o.rulesPaths[0], "-o",
                     (dir / "face").string()});
  ASSERT_EQ(gen.status, 0) << gen.output;
  EXPECT_NE(gen.output.find(fmt::format("total cost {}\n", p.headerTotal)), std::string::npos) << gen.output;
}

TEST_F(DawnExplain, AlternativesMatchIndependentSearches) {
  const Parsed& p = *parsed_;
  ASSERT_FALSE(p.rows.empty());
  int alternatives = 0;
  for (const auto& [rule, r] : p.rows) {
    // Independently: the whole pipeline with the rule banned, and a different heuristic.
    GenerateOptions o = dawnOptions();
    o.bannedRules = {rule};
    o.heuristic = "hmax";
    bool found = true;
    int64_t cost = 0;
    try {
      cost = generate(o).plan.cost;
    } catch (const InputError&) {
      found = false;
    }
    EXPECT_EQ(r.alternative, found) << rule;
    if (found && r.alternative) {
      ++alternatives;
      EXPECT_EQ(r.altTotal, cost) << rule;
      EXPECT_EQ(r.extra, cost - p.headerTotal) << rule;
      EXPECT_GE(r.extra, 0) << rule << ": the chosen plan is optimal";
    }
  }
  EXPECT_GE(alternatives, 5) << "Dawn's rules offer several alternatives (skinning, N.V, dapple...)";
  // Spot checks from the rules: blending the matrix once beats skinning three vectors.
  ASSERT_TRUE(p.rows.count("skin_matrix_blend"));
  EXPECT_TRUE(p.rows.at("skin_matrix_blend").alternative);
  EXPECT_GT(p.rows.at("skin_matrix_blend").extra, 0);
  EXPECT_NE(cli_->output.find("world_position_from_matrix               world.position               3     2  total 110 (+13) using world_position_linear_blend"),
            std::string::npos)
      << cli_->output;
}

TEST(Explain, LibraryAgreesWithCli) {
  LoadedInputs in = loadInputs(dawnOptions());
  auto plan = searchPlan(in.problem, "lmcut");
  ASSERT_TRUE(plan);
  ExplainOptions eo;
  Explanation e = explainPlan(in, *plan, eo);
  ASSERT_EQ(e.steps.size(), plan->actions.size());
  for (const auto& s : e.steps) {
    if (!s.alternative.exists) continue;
    auto q = withoutRules(in.problem, {in.problem.actions[s.action].name});
    auto alt = searchPlan(q, "blind");
    ASSERT_TRUE(alt);
    EXPECT_EQ(s.alternative.planCost, alt->cost);
  }
}

TEST(Explain, ImpossibleRequestNamesMissingInputs) {
  // The Dawn rig without its tangent stream: the tangent frame cannot be built.
  std::string rig = sg::testing::readFile(dawn("face.rig.yaml"));
  std::string noTangent;
  std::istringstream in(rig);
  for (std::string line; std::getline(in, line);)
    if (line.find("tangent:") == std::string::npos) noTangent += line + "\n";
  auto dir = sg::testing::scratchDir("explain_impossible");
  std::string rigPath = sg::testing::writeFile(dir / "no_tangent.rig.yaml", noTangent);
  auto r = runCli({"explain", "--rig", rigPath, "-f", dawn("face.frag"), "-r", dawn("rules.yaml")});
  EXPECT_EQ(r.status, 1) << r.output;
  for (const char* row : {"frame.row_x", "frame.row_y", "frame.row_z"})
    EXPECT_NE(r.output.find(fmt::format("cannot produce '{}' (requested by WorldTanMatrix", row)), std::string::npos)
        << r.output;
  // The plain tangent is offered, not only the encoded forms that decode to it.
  EXPECT_NE(r.output.find("{vertex.tangent, vertex.handedness}"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("cannot produce 'world.eye_dir'"), std::string::npos) << "only unreachable goals";
}

TEST(Explain, MinimalMissingInputSets) {
  // Hand-built: g needs (a and b) or c; a is provided; b and c are missing; d is unrelated.
  Problem p;
  for (const char* n : {"a", "b", "c", "g", "m"}) {
    Fact f;
    f.name = n;
    p.facts.push_back(f);
  }
  p.init = {0};
  auto action = [&](const char* name, std::vector<int> pre, int add) {
    Action a;
    a.name = name;
    a.pre = pre;
    a.add = add;
    a.cost = 1;
    p.actions.push_back(a);
  };
  action("m_from_ab", {0, 1}, 4);
  action("g_from_m", {4}, 3);
  action("g_from_c", {2}, 3);
  p.goals = {3};
  RuleSet rules;
  auto goals = analyzeUnreachable(p, rules, {});
  ASSERT_EQ(goals.size(), 1u);
  std::vector<std::vector<std::string>> expect{{"b"}, {"c"}};
  EXPECT_EQ(goals[0].missingInputs, expect);
  EXPECT_EQ(formatUnreachable(p, goals), "cannot produce 'g': possible if the rig also provided {b} or {c}\n");
}

}  // namespace
}  // namespace sg
