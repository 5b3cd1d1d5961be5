// Instruction weights: docs/cost-model.md (keep the two in step).
#include "analysis/cost.h"

#define SPV_ENABLE_UTILITY_CODE
#include <fmt/format.h>
#include <glslang/SPIRV/GLSL.std.450.h>
#include <glslang/SPIRV/spirv.hpp>
#include <spirv-tools/libspirv.h>

#include <algorithm>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include "emit/spirv.h"
#include "rig/rig.h"

namespace sg {
namespace {

struct Inst {
  spv::Op op = spv::OpNop;
  uint32_t type = 0;    // result type id (0 if none)
  uint32_t result = 0;  // result id (0 if none)
  std::vector<uint32_t> operands;  // words after result type / result id
};

const char* opName(spv::Op op) {
  switch (op) {
    case spv::OpFAdd: return "OpFAdd";
    case spv::OpFSub: return "OpFSub";
    case spv::OpFMul: return "OpFMul";
    case spv::OpFDiv: return "OpFDiv";
    case spv::OpFMod: return "OpFMod";
    case spv::OpFRem: return "OpFRem";
    case spv::OpFNegate: return "OpFNegate";
    case spv::OpIAdd: return "OpIAdd";
    case spv::OpISub: return "OpISub";
    case spv::OpIMul: return "OpIMul";
    case spv::OpUDiv: return "OpUDiv";
    case spv::OpSDiv: return "OpSDiv";
    case spv::OpUMod: return "OpUMod";
    case spv::OpSMod: return "OpSMod";
    case spv::OpVectorTimesScalar: return "OpVectorTimesScalar";
    case spv::OpMatrixTimesScalar: return "OpMatrixTimesScalar";
    case spv::OpVectorTimesMatrix: return "OpVectorTimesMatrix";
    case spv::OpMatrixTimesVector: return "OpMatrixTimesVector";
    case spv::OpMatrixTimesMatrix: return "OpMatrixTimesMatrix";
    case spv::OpOuterProduct: return "OpOuterProduct";
    case spv::OpTranspose: return "OpTranspose";
    case spv::OpDot: return "OpDot";
    case spv::OpLoad: return "OpLoad";
    case spv::OpStore: return "OpStore";
    case spv::OpAccessChain: return "OpAccessChain";
    case spv::OpInBoundsAccessChain: return "OpInBoundsAccessChain";
    case spv::OpCompositeConstruct: return "OpCompositeConstruct";
    case spv::OpCompositeExtract: return "OpCompositeExtract";
    case spv::OpCompositeInsert: return "OpCompositeInsert";
    case spv::OpVectorShuffle: return "OpVectorShuffle";
    case spv::OpVectorExtractDynamic: return "OpVectorExtractDynamic";
    case spv::OpVectorInsertDynamic: return "OpVectorInsertDynamic";
    case spv::OpCopyObject: return "OpCopyObject";
    case spv::OpBitcast: return "OpBitcast";
    case spv::OpConvertFToU: return "OpConvertFToU";
    case spv::OpConvertFToS: return "OpConvertFToS";
    case spv::OpConvertSToF: return "OpConvertSToF";
    case spv::OpConvertUToF: return "OpConvertUToF";
    case spv::OpSelect: return "OpSelect";
    case spv::OpPhi: return "OpPhi";
    case spv::OpVariable: return "OpVariable";
    case spv::OpExtInst: return "OpExtInst";
    case spv::OpFOrdLessThan: return "OpFOrdLessThan";
    case spv::OpFOrdGreaterThan: return "OpFOrdGreaterThan";
    case spv::OpFOrdLessThanEqual: return "OpFOrdLessThanEqual";
    case spv::OpFOrdGreaterThanEqual: return "OpFOrdGreaterThanEqual";
    case spv::OpFOrdEqual: return "OpFOrdEqual";
    case spv::OpFUnordNotEqual: return "OpFUnordNotEqual";
    case spv::OpFunctionCall: return "OpFunctionCall";
    default: return nullptr;
  }
}

std::string glslExtName(uint32_t inst) {
  static const std::map<uint32_t, const char*> names{
      {GLSLstd450FAbs, "FAbs"},       {GLSLstd450FSign, "FSign"},     {GLSLstd450Floor, "Floor"},
      {GLSLstd450Ceil, "Ceil"},       {GLSLstd450Fract, "Fract"},     {GLSLstd450Sin, "Sin"},
      {GLSLstd450Cos, "Cos"},         {GLSLstd450Pow, "Pow"},         {GLSLstd450Exp, "Exp"},
      {GLSLstd450Log, "Log"},         {GLSLstd450Exp2, "Exp2"},       {GLSLstd450Log2, "Log2"},
      {GLSLstd450Sqrt, "Sqrt"},       {GLSLstd450InverseSqrt, "InverseSqrt"},
      {GLSLstd450FMin, "FMin"},       {GLSLstd450FMax, "FMax"},       {GLSLstd450FClamp, "FClamp"},
      {GLSLstd450FMix, "FMix"},       {GLSLstd450Step, "Step"},       {GLSLstd450SmoothStep, "SmoothStep"},
      {GLSLstd450Fma, "Fma"},         {GLSLstd450Length, "Length"},   {GLSLstd450Distance, "Distance"},
      {GLSLstd450Cross, "Cross"},     {GLSLstd450Normalize, "Normalize"},
      {GLSLstd450FaceForward, "FaceForward"}, {GLSLstd450Reflect, "Reflect"}, {GLSLstd450Refract, "Refract"},
      {GLSLstd450Determinant, "Determinant"}, {GLSLstd450MatrixInverse, "MatrixInverse"}};
  auto it = names.find(inst);
  return it != names.end() ? it->second : fmt::format("#{}", inst);
}

// Vertex-program slots of a GLSL.std.450 instruction (docs/cost-model.md).
int64_t glslExtSlots(uint32_t inst) {
  switch (inst) {
    case GLSLstd450Normalize: return 3;    // DP3, RSQ, MUL
    case GLSLstd450Length: return 3;       // DP3, RSQ, RCP
    case GLSLstd450Distance: return 4;     // ADD + length
    case GLSLstd450Cross: return 2;        // MUL, MAD with swizzles
    case GLSLstd450Sqrt: return 2;         // RSQ, RCP
    case GLSLstd450Pow: return 3;          // LG2, MUL, EX2
    case GLSLstd450Exp: return 2;          // MUL, EX2
    case GLSLstd450Log: return 2;          // LG2, MUL
    case GLSLstd450Reflect: return 3;      // DP3, MUL, MAD
    case GLSLstd450Refract: return 8;
    case GLSLstd450FaceForward: return 3;  // DP3, SLT, MAD
    case GLSLstd450FClamp: return 2;       // MIN, MAX
    case GLSLstd450FMix: return 2;         // ADD, MAD
    case GLSLstd450FSign: return 2;        // SLT, SLT-difference
    case GLSLstd450SmoothStep: return 4;
    case GLSLstd450Determinant: return 8;
    case GLSLstd450MatrixInverse: return 30;
    default: return 1;  // FAbs, Floor, Fract, Exp2, Log2, InverseSqrt, Min, Max, Step, Fma, Sin, Cos...
  }
}

}  // namespace

CostBreakdown measureSpirv(const std::vector<uint32_t>& words) {
  // Decode every instruction; remember types, constants and where functions are.
  std::vector<Inst> all;
  std::vector<bool> inFunction;
  bool fn = false;
  for (size_t i = 5; i < words.size();) {
    uint32_t len = words[i] >> 16;
    if (len == 0 || i + len > words.size()) break;
    Inst in;
    in.op = static_cast<spv::Op>(words[i] & 0xffffu);
    bool hasResult = false, hasType = false;
    spv::HasResultAndType(in.op, &hasResult, &hasType);
    size_t w = i + 1;
    if (hasType && w < i + len) in.type = words[w++];
    if (hasResult && w < i + len) in.result = words[w++];
    in.operands.assign(words.begin() + static_cast<long>(w), words.begin() + static_cast<long>(i + len));
    if (in.op == spv::OpFunction) fn = true;
    all.push_back(std::move(in));
    inFunction.push_back(fn);
    if (all.back().op == spv::OpFunctionEnd) fn = false;
    i += len;
  }
  std::map<uint32_t, uint32_t> matrixColumns;  // type id -> columns
  std::set<uint32_t> constants;
  std::set<uint32_t> glslExt;
  std::map<uint32_t, const Inst*> def;
  for (const auto& in : all) {
    if (in.result) def[in.result] = &in;
    switch (in.op) {
      case spv::OpTypeMatrix:
        if (in.operands.size() >= 2) matrixColumns[in.result] = in.operands[1];
        break;
      case spv::OpConstant: case spv::OpConstantComposite: case spv::OpConstantTrue: case spv::OpConstantFalse:
      case spv::OpConstantNull: case spv::OpSpecConstant: case spv::OpSpecConstantComposite:
      case spv::OpSpecConstantTrue: case spv::OpSpecConstantFalse: case spv::OpSpecConstantOp:
        constants.insert(in.result);
        break;
      case spv::OpExtInstImport: {
        std::string name(reinterpret_cast<const char*>(in.operands.data()), in.operands.size() * 4);
        name = name.c_str();
        if (name == "GLSL.std.450") glslExt.insert(in.result);
        break;
      }
      default: break;
    }
  }
  auto columnsOf = [&](uint32_t value) -> int64_t {
    auto d = def.find(value);
    if (d == def.end()) return 1;
    auto m = matrixColumns.find(d->second->type);
    return m == matrixColumns.end() ? 1 : m->second;
  };
  // The vertex-program register a value is read from: extracts and shuffles read their
  // composite; loads read their variable; an access chain selects a register by its
  // indices, except a last index that picks a scalar component of a vector.
  std::map<uint32_t, uint32_t> pointee;  // pointer type -> pointee type
  std::set<uint32_t> scalarTypes;
  for (const auto& in : all) {
    if (in.op == spv::OpTypePointer && in.operands.size() >= 2) pointee[in.result] = in.operands[1];
    if (in.op == spv::OpTypeFloat || in.op == spv::OpTypeInt || in.op == spv::OpTypeBool) scalarTypes.insert(in.result);
  }
  std::function<std::string(uint32_t)> registerOf = [&](uint32_t id) -> std::string {
    auto d = def.find(id);
    if (d == def.end()) return std::to_string(id);
    const Inst& in = *d->second;
    if ((in.op == spv::OpCompositeExtract || in.op == spv::OpVectorShuffle || in.op == spv::OpLoad ||
         in.op == spv::OpCopyObject) && !in.operands.empty())
      return registerOf(in.operands[0]);
    if ((in.op == spv::OpAccessChain || in.op == spv::OpInBoundsAccessChain) && !in.operands.empty()) {
      size_t n = in.operands.size();
      auto pt = pointee.find(in.type);
      if (n > 1 && pt != pointee.end() && scalarTypes.count(pt->second)) --n;
      std::string key = registerOf(in.operands[0]);
      for (size_t k = 1; k < n; ++k) key += "/" + std::to_string(in.operands[k]);
      return key;
    }
    return std::to_string(id);
  };
  auto resultColumns = [&](const Inst& in) -> int64_t {
    auto m = matrixColumns.find(in.type);
    return m == matrixColumns.end() ? 1 : m->second;
  };

  // Id operands of an instruction (literal operands skipped for the opcodes that have them).
  auto idOperands = [](const Inst& in) {
    std::vector<uint32_t> ids = in.operands;
    switch (in.op) {
      case spv::OpCompositeExtract: ids.resize(std::min<size_t>(1, ids.size())); break;
      case spv::OpCompositeInsert: ids.resize(std::min<size_t>(2, ids.size())); break;
      case spv::OpVectorShuffle: ids.resize(std::min<size_t>(2, ids.size())); break;
      case spv::OpLoad: ids.resize(std::min<size_t>(1, ids.size())); break;
      case spv::OpStore: ids.resize(std::min<size_t>(2, ids.size())); break;
      case spv::OpExtInst:
        if (ids.size() >= 2) ids.erase(ids.begin(), ids.begin() + 2);
        break;
      default: break;
    }
    return ids;
  };
  std::map<uint32_t, std::vector<size_t>> uses;  // id -> indices (in `all`) of function instructions using it
  for (size_t k = 0; k < all.size(); ++k)
    if (inFunction[k])
      for (uint32_t id : idOperands(all[k])) uses[id].push_back(k);

  // Multiply-add fusion: a multiply whose every use is an add (directly, or through the
  // column extracts of a matrix) becomes the MUL half of MADs. Each add absorbs one multiply.
  auto isAdd = [&](size_t k) { return all[k].op == spv::OpFAdd || all[k].op == spv::OpFSub; };
  std::set<size_t> absorbed;  // adds that already took a multiply
  std::set<uint32_t> fused;
  for (size_t k = 0; k < all.size(); ++k) {
    const Inst& in = all[k];
    if (!inFunction[k] || !(in.op == spv::OpFMul || in.op == spv::OpVectorTimesScalar ||
                            in.op == spv::OpMatrixTimesScalar))
      continue;
    std::vector<size_t> adds;
    bool ok = !uses[in.result].empty();
    for (size_t u : uses[in.result]) {
      if (isAdd(u)) {
        adds.push_back(u);
      } else if (all[u].op == spv::OpCompositeExtract && in.op == spv::OpMatrixTimesScalar &&
                 !uses[all[u].result].empty()) {
        for (size_t v : uses[all[u].result]) {
          if (isAdd(v)) adds.push_back(v);
          else ok = false;
        }
      } else {
        ok = false;
      }
    }
    for (size_t a : adds)
      if (absorbed.count(a)) ok = false;
    if (!ok) continue;
    absorbed.insert(adds.begin(), adds.end());
    fused.insert(in.result);
  }

  std::map<std::string, CostItem> items;
  auto add = [&](const std::string& what, int64_t slots) {
    CostItem& it = items[what];
    it.what = what;
    it.count += 1;
    it.slots += slots;
  };
  for (size_t k = 0; k < all.size(); ++k) {
    if (!inFunction[k]) continue;
    const Inst& in = all[k];
    const char* name = opName(in.op);
    std::string what = name ? name : fmt::format("Op#{}", static_cast<int>(in.op));
    switch (in.op) {
      // Structure, memory and register moves the hardware does for free.
      case spv::OpFunction: case spv::OpFunctionEnd: case spv::OpFunctionParameter: case spv::OpLabel:
      case spv::OpReturn: case spv::OpReturnValue: case spv::OpBranch: case spv::OpSelectionMerge:
      case spv::OpLoopMerge: case spv::OpLine: case spv::OpNoLine: case spv::OpNop:
        break;
      case spv::OpVariable: case spv::OpLoad: case spv::OpStore: case spv::OpCompositeExtract:
      case spv::OpVectorShuffle: case spv::OpCopyObject: case spv::OpBitcast: case spv::OpUndef:
      case spv::OpFNegate: case spv::OpPhi: case spv::OpFunctionCall:
        add(what, 0);
        break;
      case spv::OpAccessChain: case spv::OpInBoundsAccessChain: {
        // Constant indices are free; a dynamic index needs an address register load (ARL).
        int64_t dyn = 0;
        for (size_t o = 1; o < in.operands.size(); ++o)
          if (!constants.count(in.operands[o])) ++dyn;
        add(dyn ? what + " (dynamic index)" : what, dyn);
        break;
      }
      case spv::OpCompositeConstruct: {
        if (matrixColumns.count(in.type)) {
          add(what + " (matrix)", 0);
          break;
        }
        // One write-masked MOV per distinct source register; a pure swizzle of one
        // register is free, and constants come from constant registers.
        std::set<std::string> sources;
        bool anyConstant = false;
        for (uint32_t c : in.operands) {
          if (constants.count(c)) {
            anyConstant = true;
            continue;
          }
          sources.insert(registerOf(c));
        }
        int64_t moves = static_cast<int64_t>(sources.size());
        if (moves == 1 && !anyConstant) moves = 0;
        add(what, moves);
        break;
      }
      case spv::OpFMul: case spv::OpVectorTimesScalar: case spv::OpMatrixTimesScalar:
        if (fused.count(in.result)) add(what + " (fused into a multiply-add)", 0);
        else add(what, in.op == spv::OpMatrixTimesScalar ? resultColumns(in) : 1);
        break;
      case spv::OpMatrixTimesVector:
        add(what, in.operands.empty() ? 4 : columnsOf(in.operands[0]));
        break;
      case spv::OpVectorTimesMatrix:
        add(what, in.operands.size() < 2 ? 4 : columnsOf(in.operands[1]));
        break;
      case spv::OpMatrixTimesMatrix:
        add(what, in.operands.size() < 2 ? 16 : columnsOf(in.operands[0]) * columnsOf(in.operands[1]));
        break;
      case spv::OpTranspose: case spv::OpOuterProduct:
        add(what, resultColumns(in));
        break;
      case spv::OpFDiv: case spv::OpUDiv: case spv::OpSDiv:
        add(what, 2);  // RCP, MUL
        break;
      case spv::OpFMod: case spv::OpFRem: case spv::OpUMod: case spv::OpSMod:
        add(what, 3);
        break;
      case spv::OpExtInst:
        if (in.operands.size() >= 2 && glslExt.count(in.operands[0]))
          add("GLSL.std.450 " + glslExtName(in.operands[1]), glslExtSlots(in.operands[1]));
        else
          add(what, 1);
        break;
      default:
        add(what, 1);  // other arithmetic, comparisons, selects, conversions
        break;
    }
  }
  CostBreakdown b;
  for (auto& [k, it] : items) {
    b.total += it.slots;
    b.items.push_back(it);
  }
  return b;
}

namespace {

// The rule's probe compiled and optimised; `forAccesses`: the access probe (probe.h), its loops
// of constant trip count unrolled. nullopt with the reasons in `diags` (located in the rules file).
std::optional<std::vector<uint32_t>> optimisedProbe(const RuleSet& rules, int r, const ProbeRig& rig, bool forAccesses,
                                                    SnippetProbe& probe, std::vector<Diagnostic>& diags) {
  const Rule& rule = rules.rules[static_cast<size_t>(r)];
  try {
    probe = buildSnippetProbe(rules, r, rig, forAccesses);
  } catch (const InputError& e) {
    diags.push_back(e.diagnostic());
    return std::nullopt;
  }
  CompileResult c = compileSnippetProbe(probe, rule);
  if (!c.ok) {
    // glslang's trailing "compilation terminated" adds nothing, nor do errors that cascade
    // from the first one on the same line.
    std::set<std::pair<std::string, int>> lines;
    for (const auto& d : c.diagnostics)
      if (d.severity == Severity::Error && d.message.find("compilation terminated") == std::string::npos &&
          (d.loc.line == 0 || lines.insert({d.loc.file, d.loc.line}).second))
        diags.push_back(d);
    if (diags.empty())
      diags.push_back(Diagnostic{Severity::Error, rule.loc,
                                 fmt::format("the snippet of rule '{}' does not compile", rule.name)});
    return std::nullopt;
  }
  try {
    return optimizeSpirv(c.spirv, TargetEnv::Vulkan1_0, forAccesses);
  } catch (const std::exception& e) {
    diags.push_back(Diagnostic{Severity::Error, rule.loc,
                               fmt::format("rule '{}': cannot optimise its snippet: {}", rule.name, e.what())});
    return std::nullopt;
  }
}

}  // namespace

AutoCost measureRuleCost(const RuleSet& rules, int r, const ProbeRig& rig) {
  AutoCost res;
  SnippetProbe probe;
  std::optional<std::vector<uint32_t>> opt = optimisedProbe(rules, r, rig, false, probe, res.diagnostics);
  if (!opt) return res;
  res.breakdown = measureSpirv(*opt);
  res.cost = res.breakdown.total;
  res.ok = true;
  return res;
}

namespace {

// Ids whose value may differ between the vertices of one draw: loaded from a vertex input
// (an attribute, gl_VertexIndex), or computed from, or loaded at an index computed from, such
// a value. A uniform-array read at any other computed index (u_weight[u_active[k]]) reads one
// address for a whole warp, as a constant index does. SPIRV-Tools' parser tells id operands
// from literals; stores into function variables and phis are followed to a fixed point.
std::set<uint32_t> perVertexIds(const std::vector<uint32_t>& words) {
  struct Parsed {
    spv::Op op;
    uint32_t result;
    std::vector<uint32_t> ids;  // id operands (not types, not literals)
  };
  struct Acc {
    std::vector<Parsed> insts;
    std::set<uint32_t> inputs;  // variables of the Input storage class
  } acc;
  auto onInst = [](void* user, const spv_parsed_instruction_t* in) -> spv_result_t {
    auto* a = static_cast<Acc*>(user);
    Parsed p{static_cast<spv::Op>(in->opcode), in->result_id, {}};
    for (uint16_t k = 0; k < in->num_operands; ++k)
      if (in->operands[k].type == SPV_OPERAND_TYPE_ID) p.ids.push_back(in->words[in->operands[k].offset]);
    if (p.op == spv::OpVariable && in->num_words >= 4 && in->words[3] == spv::StorageClassInput) a->inputs.insert(in->result_id);
    a->insts.push_back(std::move(p));
    return SPV_SUCCESS;
  };
  spv_context ctx = spvContextCreate(SPV_ENV_VULKAN_1_0);
  const spv_result_t ok = spvBinaryParse(ctx, &acc, words.data(), words.size(), nullptr, onInst, nullptr);
  spvContextDestroy(ctx);
  std::set<uint32_t> varying(acc.inputs.begin(), acc.inputs.end());
  if (ok != SPV_SUCCESS) return varying;
  std::map<uint32_t, uint32_t> root;  // access chain -> the variable it starts from
  for (const auto& p : acc.insts)
    if ((p.op == spv::OpAccessChain || p.op == spv::OpInBoundsAccessChain) && !p.ids.empty())
      root[p.result] = root.count(p.ids[0]) ? root[p.ids[0]] : p.ids[0];
  for (bool changed = true; changed;) {
    changed = false;
    for (const auto& p : acc.insts) {
      if (p.op == spv::OpStore) {  // a function variable holding a per-vertex value
        if (p.ids.size() >= 2 && varying.count(p.ids[1])) {
          const uint32_t var = root.count(p.ids[0]) ? root[p.ids[0]] : p.ids[0];
          changed = varying.insert(var).second || changed;
        }
        continue;
      }
      if (p.result == 0 || varying.count(p.result)) continue;
      bool v = false;
      for (uint32_t id : p.ids) v = v || varying.count(id) || (root.count(id) && varying.count(root[id]));
      if (v) changed = varying.insert(p.result).second || changed;
    }
  }
  return varying;
}

}  // namespace

SpirvAccesses measureAccesses(const std::vector<uint32_t>& words) {
  const std::set<uint32_t> perVertex = perVertexIds(words);
  SpirvAccesses out;
  std::set<uint32_t> constants, bufferBlocks;
  std::map<uint32_t, uint32_t> binding, pointerClass, pointee;  // id -> Binding; pointer type -> class, pointee
  std::map<uint32_t, uint32_t> variableType;                    // variable -> its pointer type
  std::map<uint32_t, uint32_t> constantValue;                   // 32-bit integer constants
  std::map<uint32_t, int64_t> typeBytes;                        // tightly packed size of a type
  struct Chain {
    uint32_t base;
    bool dynamic;
    std::vector<uint32_t> indices;
  };
  // Per element (variable and index values up to the last computed index): the distinct
  // loads under it (their full paths) and the bytes each reads, whether the element is
  // uniform (else a buffer) and its binding.
  struct Element {
    bool buffer = false;
    uint32_t binding = 0;
    std::map<std::vector<uint32_t>, int64_t> loads;
  };
  std::map<std::vector<uint32_t>, Element> elements;
  std::map<uint32_t, Chain> chains;  // access chain result -> its base and whether an index is computed
  auto bytesOf = [&](uint32_t t) { return typeBytes.count(t) ? typeBytes[t] : int64_t{4}; };
  for (size_t i = 5; i < words.size();) {
    const uint32_t len = words[i] >> 16;
    if (len == 0 || i + len > words.size()) break;
    const auto op = static_cast<spv::Op>(words[i] & 0xffffu);
    const uint32_t* w = &words[i];
    switch (op) {
      case spv::OpConstant:
        if (len >= 4) constantValue[w[2]] = w[3];
        [[fallthrough]];
      case spv::OpConstantComposite: case spv::OpConstantNull: case spv::OpSpecConstant:
        if (len >= 3) constants.insert(w[2]);
        break;
      case spv::OpTypeInt: case spv::OpTypeFloat:
        if (len >= 3) typeBytes[w[1]] = w[2] / 8;
        break;
      case spv::OpTypeVector: case spv::OpTypeMatrix:
        if (len >= 4) typeBytes[w[1]] = bytesOf(w[2]) * w[3];
        break;
      case spv::OpTypeArray:
        if (len >= 4) typeBytes[w[1]] = bytesOf(w[2]) * (constantValue.count(w[3]) ? constantValue[w[3]] : 1);
        break;
      case spv::OpTypeStruct: {
        int64_t b = 0;
        for (uint32_t k = 2; k < len; ++k) b += bytesOf(w[k]);
        typeBytes[w[1]] = b;
        break;
      }
      case spv::OpDecorate:
        if (len >= 4 && w[2] == spv::DecorationBinding) binding[w[1]] = w[3];
        if (len >= 3 && w[2] == spv::DecorationBufferBlock) bufferBlocks.insert(w[1]);
        break;
      case spv::OpTypePointer:
        if (len >= 4) {
          pointerClass[w[1]] = w[2];
          pointee[w[1]] = w[3];
        }
        break;
      case spv::OpVariable:
        if (len >= 4) variableType[w[2]] = w[1];
        break;
      case spv::OpAccessChain: case spv::OpInBoundsAccessChain:
        if (len >= 4) {
          bool dynamic = false;
          for (uint32_t k = 4; k < len; ++k) dynamic = dynamic || perVertex.count(w[k]);
          chains[w[2]] = Chain{w[3], dynamic, std::vector<uint32_t>(w + 4, w + len)};
        }
        break;
      case spv::OpLoad: {
        if (len < 4) break;
        uint32_t ptr = w[3];
        bool dynamic = false;
        std::vector<uint32_t> path;  // the indices from the variable down, innermost chain last
        for (auto c = chains.find(ptr); c != chains.end(); c = chains.find(ptr)) {
          dynamic = dynamic || c->second.dynamic;
          path.insert(path.begin(), c->second.indices.begin(), c->second.indices.end());
          ptr = c->second.base;
        }
        auto var = variableType.find(ptr);
        if (var == variableType.end()) break;
        const uint32_t cls = pointerClass[var->second];
        const bool buffer = cls == spv::StorageClassStorageBuffer ||
                            (cls == spv::StorageClassUniform && bufferBlocks.count(pointee[var->second]));
        if (!buffer && !(cls == spv::StorageClassUniform && dynamic)) break;
        path.insert(path.begin(), ptr);
        // The element: the path up to the last computed index; constant indices after it
        // pick parts of the element (a component of a vec4, a column of a palette matrix).
        std::vector<uint32_t> element = path;
        for (size_t k = element.size(); k-- > 1;)
          if (!constants.count(element[k])) {
            element.resize(k + 1);
            break;
          }
        Element& e = elements[element];
        e.buffer = buffer;
        e.binding = binding.count(ptr) ? binding[ptr] : 0;
        e.loads.emplace(path, bytesOf(w[1]));
        break;
      }
      default: break;
    }
    i += len;
  }
  for (const auto& [path, e] : elements) {
    // Bytes of the element read: the whole element when it is loaded whole, else its
    // distinct parts; a device fetches them 16 bytes (one vec4) per load.
    int64_t bytes = 0;
    if (auto whole = e.loads.find(path); whole != e.loads.end()) bytes = whole->second;
    else
      for (const auto& [part, b] : e.loads) bytes += b;
    const int64_t loads = std::max<int64_t>(1, (bytes + 15) / 16);
    if (e.buffer) {
      ++out.bufferLoads[e.binding];
      out.bufferVec4Loads[e.binding] += loads;
    } else {
      ++out.indexedUniformLoads;
      out.indexedUniformVec4Loads += loads;
    }
  }
  return out;
}

RuleAccesses measureRuleAccesses(const RuleSet& rules, int r, const ProbeRig& rig) {
  RuleAccesses res;
  SnippetProbe probe;
  std::optional<std::vector<uint32_t>> opt = optimisedProbe(rules, r, rig, true, probe, res.diagnostics);
  if (!opt) return res;
  SpirvAccesses a = measureAccesses(*opt);
  for (const auto& [b, loads] : a.bufferLoads)
    if (b >= 1 && b <= probe.buffers.size()) res.bufferLoads[probe.buffers[b - 1]] += loads;
  for (const auto& [b, n] : a.bufferVec4Loads)
    if (b >= 1 && b <= probe.buffers.size()) res.bufferVec4Loads[probe.buffers[b - 1]] += n;
  res.indexedUniformVec4Loads = a.indexedUniformVec4Loads;
  res.indexedUniformLoads = a.indexedUniformLoads;
  res.ok = true;
  return res;
}

void measureAccessTerms(Problem& p, const RuleSet& rules, const Rig& rig) {
  std::optional<ProbeRig> pr;
  std::map<int, RuleAccesses> measured;  // per rule
  for (auto& act : p.actions) {
    // Only a rule that reads a storage buffer or a uniform array can load either.
    bool reads = false;
    for (int q : act.pre) {
      const Fact& f = p.facts[static_cast<size_t>(q)];
      reads = reads || f.source == Fact::Source::Buffer || (f.source == Fact::Source::Uniform && f.arraySize > 0);
    }
    if (!reads) continue;
    if (!pr) pr = probeRigFromRig(rig, rules);
    auto it = measured.find(act.rule);
    if (it == measured.end()) it = measured.emplace(act.rule, measureRuleAccesses(rules, act.rule, *pr)).first;
    const RuleAccesses& a = it->second;
    if (!a.ok) {
      InputError e(a.diagnostics.front());
      e.related.assign(a.diagnostics.begin() + 1, a.diagnostics.end());
      throw e;
    }
    act.terms[kTermBufferLoads] = act.terms[kTermBufferBytes] = act.terms[kTermBufferVec4Loads] = 0;
    act.terms[kTermBufferTableLoads] = act.terms[kTermBufferTableVec4Loads] = 0;
    for (const auto& [fact, elements] : a.bufferLoads) {
      const int f = p.findFact(fact);
      if (f < 0 || p.facts[static_cast<size_t>(f)].source != Fact::Source::Buffer) continue;
      const Fact& bf = p.facts[static_cast<size_t>(f)];
      const BufferSource& b = p.buffers[static_cast<size_t>(bf.rigIndex)];
      // The probe reads the semantic's own type; the program reads the buffer's layout:
      // tightly packed floats take one scalar load per component (glsl_emitter's accessor).
      auto loads = a.bufferVec4Loads.find(fact);
      const bool table = b.kind == BufferSource::Kind::Array;  // read at a joint, not at the vertex
      act.terms[table ? kTermBufferTableLoads : kTermBufferLoads] += elements;
      act.terms[table ? kTermBufferTableVec4Loads : kTermBufferVec4Loads] +=
          b.element == Type::Float ? elements * componentCount(bf.type)
                                   : (loads == a.bufferVec4Loads.end() ? elements : loads->second);
      act.terms[kTermBufferBytes] += elements * b.strideBytes;
    }
    act.terms[kTermIndexedUniformLoads] = a.indexedUniformLoads;
    act.terms[kTermIndexedUniformVec4Loads] = a.indexedUniformVec4Loads;
  }
  shareIndexedUniformLoads(p);
  priceProblem(p, p.weights);
}

void shareIndexedUniformLoads(Problem& p) {
  // Per uniform array: whether every rule reading it reads no other uniform array and loads
  // it at a per-vertex index, and the most loads one of them makes.
  struct Readers {
    bool shareable = true;
    TermAmounts most{};
    std::vector<size_t> actions;
  };
  std::map<int, Readers> arrays;  // by fact
  for (size_t i = 0; i < p.actions.size(); ++i) {
    const Action& act = p.actions[i];
    std::vector<int> read;
    for (int q : act.pre) {
      const Fact& f = p.facts[static_cast<size_t>(q)];
      if (f.source == Fact::Source::Uniform && f.arraySize > 0) read.push_back(q);
    }
    for (int q : read) {
      Readers& r = arrays[q];
      r.actions.push_back(i);
      r.shareable = r.shareable && read.size() == 1 && act.terms[kTermIndexedUniformLoads] > 0 &&
                    p.facts[static_cast<size_t>(q)].resource >= 0;
      for (int t : {kTermIndexedUniformLoads, kTermIndexedUniformVec4Loads})
        r.most[t] = std::max(r.most[t], act.terms[t]);
    }
  }
  for (auto& [fact, r] : arrays) {
    if (!r.shareable) continue;
    ResourceItem& item = p.resources[static_cast<size_t>(p.facts[static_cast<size_t>(fact)].resource)];
    for (int t : {kTermIndexedUniformLoads, kTermIndexedUniformVec4Loads}) {
      item.terms[t] = r.most[t];
      for (size_t a : r.actions) p.actions[a].terms[t] = 0;
    }
  }
}

void resolveAutoCosts(RuleSet& rules, const Rig& rig) {
  bool any = false;
  for (const auto& r : rules.rules) any = any || (r.costAuto && r.cost.empty());
  if (!any) return;
  ProbeRig pr = probeRigFromRig(rig, rules);
  ExprEnv env = probeEnv(pr);
  for (size_t i = 0; i < rules.rules.size(); ++i) {
    Rule& rule = rules.rules[i];
    if (!rule.costAuto || !rule.cost.empty()) continue;
    if (!rule.when.empty()) {
      bool applies = true;
      try {
        applies = rule.when.eval(env) != 0;
      } catch (const InputError&) {
        continue;  // instantiation reports it
      }
      if (!applies) continue;
    }
    AutoCost c = measureRuleCost(rules, static_cast<int>(i), pr);
    if (!c.ok) {
      InputError e(c.diagnostics.front());
      e.related.assign(c.diagnostics.begin() + 1, c.diagnostics.end());
      throw e;
    }
    rule.cost = Expr::parse(std::to_string(c.cost), rule.loc);
  }
}

}  // namespace sg
