// The search problem: rules instantiated against a rig. Facts are semantic
// instances; actions are rule instances (one product, a set of preconditions, a
// cost, and their unrolled snippet). Delete-free: applying an action only adds.
#pragma once
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "common/diagnostics.h"
#include "common/types.h"

namespace sg {

struct Plan;
struct Rig;
struct RuleSet;
struct Varying;

struct Fact {
  enum class Source { Computed, Attribute, Uniform, Buffer };
  std::string name;  // "world.normal", "morph.position[3]"
  Type type = Type::Vec3;
  int arraySize = 0;  // uniform arrays
  Source source = Source::Computed;
  int rigIndex = -1;    // attribute or uniform index in the rig; Buffer: index in Problem::buffers
  int target = -1;      // morph target of a per-target attribute
  std::string swizzle;  // part of the attribute ("" = whole)
  int resource = -1;    // the ResourceItem reading this fact occupies (-1: none)
};

// Device limits are constraints, not costs (docs/search.md, "Resource limits"). Every rig
// input a plan reads occupies a resource item (an attribute stream takes vertex input
// locations, a uniform takes bytes of the uniform block); a plan's usage of a limit is the
// sum over the distinct items its rules' needs and its pass-through goals read.
constexpr int64_t kVulkanMinVertexAttributes = 16;  // maxVertexInputAttributes every device has
constexpr int64_t kVulkanMinUniformBytes = 16384;   // maxUniformBufferRange every device has
// The terms of the cost model (docs/device-profiles.md): what a vertex program pays for,
// each counted per vertex. A plan's cost is the weighted sum of its amounts; the weights
// are a device profile (search/device_profile.h) or, without one, the instruction-slot
// model: arithmetic 1, every other term 0 (docs/cost-model.md).
enum CostTerm {
  kTermArithmetic = 0,      // instruction slots (the rules' costs, stated or `cost: auto`)
  kTermLocations,           // vertex input locations read (an input charged once per plan)
  kTermAttributeBytes,      // bytes fetched from vertex attributes (their formats)
  kTermBufferBytes,         // bytes fetched from storage buffers (element strides)
  kTermBufferLoads,         // storage-buffer elements loaded
  kTermIndexedUniformLoads, // uniform elements loaded at an index computed per vertex (palette[joint])
  // The same loads counted as a device issues them, 16 bytes (a vec4) at most per load
  // (analysis/cost.h): a mat4 palette entry is 4, a buffer of tightly packed floats one per
  // component. Profiles from before they were counted weigh them 0 and mean what they meant.
  kTermBufferVec4Loads,
  kTermIndexedUniformVec4Loads,
  kTermOutputs,             // output components written (the varyings and gl_Position)
  kTermVertices,            // 1: the fixed cost of running the program for one vertex
  // 1: the rasterizer's and fragment shader's work that comes with drawing a vertex, priced
  // per fragment its draw covers (a profile scales it by the workload's fragments per vertex).
  // The same for every plan of a request: it moves the level of a prediction, not a choice.
  kTermFragments,
  // Storage-buffer elements of a table (an array buffer: the palette in a buffer) loaded at an
  // index computed per vertex, and their vec4 loads: counted here, not in kTermBufferLoads and
  // kTermBufferVec4Loads, which count the per-vertex streams (a morph delta, an influence). The
  // vertices of a warp read a few entries of a table through the cache and a stream's each its
  // own (docs/device-profiles.md, "Table reads"). A profile that does not name them prices
  // them as buffer loads, as it did before they were counted apart.
  kTermBufferTableLoads,
  kTermBufferTableVec4Loads,
  kTermCount
};
using TermAmounts = std::array<int64_t, kTermCount>;
// "arithmetic", "locations", ...: the keys of a device profile's `weights:`.
const char* termName(int term);
int termByName(const std::string& name);  // termName's inverse; -1 for no term
// Search cost units per unit of each term (int64: A* stays exact). Without a profile the
// unit is the instruction slot; a profile's unit is the femtosecond (docs/device-profiles.md).
using TermWeights = std::array<int64_t, kTermCount>;
constexpr TermWeights kSlotWeights = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
// sum of weight x amount (checked: a hostile profile cannot overflow it silently).
int64_t weighTerms(const TermWeights& w, const TermAmounts& a);

struct ResourceLimit {
  std::string what;    // "vertex input attributes"
  std::string option;  // how the user raises it: "--max-attributes"
  int64_t max = INT64_MAX;
};
struct ResourceItem {
  std::string name;  // "attribute a_coord_morph3", "uniform u_bone_xf"
  int limit = 0;     // index in Problem::limits
  int64_t amount = 0;
  // What reading it costs, paid once per plan however many rules read it: the amounts per
  // term (an attribute's locations and bytes) and their weighted sum (priceProblem).
  TermAmounts terms{};
  int64_t cost = 0;
};
enum ResourceLimitIndex { kLimitAttributes = 0, kLimitUniformBytes = 1, kLimitStorageBuffers = 2 };
constexpr int64_t kVulkanMinStorageBuffers = 4;  // maxPerStageDescriptorStorageBuffers every device has

// A storage buffer the rig's data can fill (a `buffer_of:` semantic, docs/buffers.md).
// PerVertex: element (vertex v, instance i) at index v * count + i, each element packing
// one instance of every family in `parts` (facts[i] of each part). Array: the elements
// of one uniform array (a joint palette), element i at index i.
struct BufferSource {
  enum class Kind { PerVertex, Array };
  Kind kind = Kind::PerVertex;
  int fact = -1;       // the buffer semantic's fact
  int64_t count = 0;   // instances per vertex (PerVertex) or elements (Array)
  // std430 array element: float (1-3 float components packed tightly, `components` floats
  // per instance), vec4, uvec4, ivec4 or mat4.
  Type element = Type::Vec4;
  int components = 4;       // floats (or uints) per instance
  int64_t strideBytes = 16;  // bytes per instance
  struct Part {
    std::string family;      // "morph.normal"
    int components = 0;      // of the element, from `firstComponent`
    int firstComponent = 0;
    std::vector<int> facts;  // the family's instances (rig attribute facts)
  };
  std::vector<Part> parts;  // PerVertex
  int uniform = -1;         // Array: the rig uniform whose values it holds
  // Set by dropOversizedBuffers when it drops this buffer: "N bytes for V vertices, over the
  // M bytes of maxStorageBufferRange". The error for a rig no plan fits quotes it.
  std::string oversize;
};

// One line of instantiated snippet. Fact references are encoded as
// kFactRefBegin <id> kFactRefEnd so the emitter picks the GLSL names.
struct CodeLine {
  std::string text;
  SourceLoc loc;  // where the template line sits in the rules file
};
constexpr char kFactRefBegin = '\x01';
constexpr char kFactRefEnd = '\x02';
std::string factRef(int fact);

// Splits "skin.joints[1]" into ("skin.joints", 1); plain names give index -1.
std::pair<std::string, int64_t> splitIndexed(const std::string& name);

struct Action {
  std::string name;  // rule name
  int rule = -1;     // index in RuleSet::rules
  std::vector<int> pre;  // sorted, unique
  int add = -1;
  int64_t cost = 0;  // weighTerms(Problem::weights, terms); the rule's cost without a profile
  std::vector<CodeLine> code;
  // Per instance of the rule: terms[kTermArithmetic] is the rule's cost in slots; buffer and
  // indexed uniform loads are measured from its snippet (analysis/cost.h measureRuleAccesses).
  TermAmounts terms{};
};

struct Problem {
  std::vector<Fact> facts;
  std::vector<Action> actions;
  std::vector<int> init;   // provided facts
  std::vector<int> goals;  // requested facts (sorted, unique)
  // Rules skipped at instantiation and why (for explain/check): "when is false", ...
  std::vector<std::pair<int, std::string>> skippedRules;
  std::map<std::string, std::string> withheld;  // the rig's (Rig::withheld)
  std::vector<ResourceLimit> limits;  // empty: unconstrained (random libraries, tests)
  std::vector<ResourceItem> resources;
  std::vector<BufferSource> buffers;
  // The cost model's weights, and what every plan pays regardless of its rules (outputs,
  // the vertex itself): fixedTerms, and fixedCost = their weighted sum, part of every plan's cost.
  TermWeights weights = kSlotWeights;
  TermAmounts fixedTerms{};
  int64_t fixedCost = 0;
  // A roofline objective (docs/search.md, "Roofline objectives"): when not empty, a plan
  // costs the LARGEST of these weighted sums of its term amounts (one per pipe a device
  // overlaps, or per device of a portable choice), each summed as `weights` is (rules, the
  // inputs read once, fixed terms). Then Action::cost and the items' costs are the largest
  // component (for reports); the engines search the components. Empty: the one sum.
  std::vector<TermWeights> componentWeights;

  int findFact(const std::string& name) const;  // -1 if absent
};

// Instantiates `rules` against `rig` for the requested `varyings`. Throws InputError for
// inconsistent inputs (rig semantics unknown to the rules, type mismatches, bad snippet
// templates, references to semantics not listed in `needs`, negative costs).
Problem buildProblem(const Rig& rig, const RuleSet& rules, const std::vector<Varying>& varyings);

// The device limits of a generation: vertex input attributes (Vulkan guarantees 16) and
// uniform block bytes (maxUniformBufferRange, 16384 guaranteed).
void setDeviceLimits(Problem& p, int64_t maxAttributes, int64_t maxUniformBytes,
                     int64_t maxStorageBuffers = kVulkanMinStorageBuffers);

// Per-vertex storage buffers larger than `maxBytes` for draws of up to `maxVertices`
// vertices (maxStorageBufferRange, 2^27 guaranteed) are not offered: their facts stop being
// provided, so the search uses other forms. maxVertices <= 0: vertex count unknown, keep all.
void dropOversizedBuffers(Problem& p, int64_t maxVertices, int64_t maxBytes);

// The distinct resource items a set of actions (and the goals the rig provides) read, ascending.
std::vector<int> itemsRead(const Problem& p, const std::vector<int>& actions);
// Usage per limit of the rig inputs a set of actions (and the goals) read.
std::vector<int64_t> resourceUsage(const Problem& p, const std::vector<int>& actions);
// Prices actions, items and the fixed terms with `w` (costs = weighTerms of their terms).
// With kSlotWeights every cost is what it was without a cost model: the rules' slots.
void priceProblem(Problem& p, const TermWeights& w);
// A roofline objective: a plan costs max over `components` of its amounts' weighted sum
// (Problem::componentWeights). One component is priceProblem; none is refused.
void priceProblemByMax(Problem& p, const std::vector<TermWeights>& components);
// What a set of actions pays per term: their terms, each input read once, the fixed terms.
TermAmounts planAmounts(const Problem& p, const std::vector<int>& actions);
// The cost of a plan with these amounts (the largest component, or the one sum); and each
// component's sum (one entry without components).
int64_t weighPlan(const Problem& p, const TermAmounts& amounts);
std::vector<int64_t> componentCosts(const Problem& p, const TermAmounts& amounts);
// Whether some resource item has a cost (the search must then track the items a plan reads).
bool hasItemCosts(const Problem& p);
// The A* engines' view of priced inputs (docs/search.md, "Device profiles"): every rig
// input with a cost becomes a fact of its own, produced by one action ("read <input>") that
// costs the input's cost and needs nothing, and every action reading the input also needs
// that fact. A delete-free plan produces a fact once, so the input is paid once however
// many rules read it, and the heuristics (LM-cut, h_max, landmarks) see the shared cost the
// way they see any shared intermediate value. Inputs of pass-through goals are read by every
// plan: their costs join fixedCost. No item has a cost in the result, and a plan of it costs
// what it costs in `p`. Actions keep their indices; planOnInputs maps a plan back.
Problem inputsAsFacts(const Problem& p);
Plan planOnInputs(const Problem& p, const Plan& onFacts);

// Vertex input locations of a shader input type (Vulkan: a matrix takes one per column,
// a 64-bit vector of 3 or 4 components two).
int vertexInputLocations(Type t);
// The first limit the usage exceeds, or -1.
int exceededLimit(const Problem& p, const std::vector<int64_t>& usage);
// "21 vertex input attributes, above the limit of 16 (--max-attributes)".
std::string describeExceeded(const Problem& p, const std::vector<int64_t>& usage, int limit);

// Same problem without the actions of the named rules (to force alternatives).
Problem withoutRules(const Problem& p, const std::vector<std::string>& ruleNames);

}  // namespace sg
