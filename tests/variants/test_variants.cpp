// `shadergen build`: manifests (every error located), the variant product, outputs
// byte-identical to one generate() per variant, the content cache across builds (only
// changed inputs regenerate; damaged entries are misses), shared SPIR-V, determinism
// whatever the thread count, and failures that leave the index out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core_test_util.h"
#include "emit/reflection.h"
#include "pipeline/generate.h"
#include "variants/builder.h"
#include "variants/cache_store.h"
#include "common/content_hash.h"
#include "variants/manifest.h"

namespace fs = std::filesystem;
using namespace sg;
using sgtest::errorOf;
using sgtest::freshDir;
using sgtest::writeText;

namespace {

const std::string kDawn = std::string(SG_SOURCE_DIR) + "/examples/dawn/";

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A small manifest over copies of the Dawn rigs (the tests edit them).
fs::path smallManifest(const fs::path& dir, const std::string& extra = "") {
  fs::copy_file(kDawn + "face.rig.yaml", dir / "face.rig.yaml");
  fs::copy_file(kDawn + "body.rig.yaml", dir / "body.rig.yaml");
  writeText(dir / "shadow.frag", "#version 450\nlayout(location = 0) out float D;\nvoid main() { D = gl_FragCoord.z; }\n");
  writeText(dir / "m.yaml", "output: out\n"
                            "rules: " + kDawn + "rules.yaml\n"
                            "rigs:\n  face: face.rig.yaml\n  body: body.rig.yaml\n"
                            "passes:\n  color: " + kDawn + "face.frag\n  depth: " + kDawn + "depth.frag\n"
                            "  shadow: shadow.frag\n"
                            "axes:\n  morph_targets: [2, 0]\n  influences: [4, 1]\n"
                            "exclude:\n  - { rig: body, morph_targets: 2 }\n" + extra);
  return dir / "m.yaml";
}

std::map<std::string, std::string> filesOf(const BuildReport& r) {
  std::map<std::string, std::string> m;
  for (const auto& f : r.files) m[f.path] = f.contents;
  return m;
}

// What one `generate` command is given for a built variant, written out here (not the
// builder's generateOptionsOf): the outputs must equal that command's.
GenerateOptions generateCommandOf(const Manifest& m, const BuiltVariant& b) {
  const Variant& v = *b.variant;
  GenerateOptions o;
  o.rigPath = v.rig->path;
  o.fragmentPath = v.pass->fragment;
  o.rulesPaths = m.rules;
  o.rigParams = v.params;
  o.outputName = b.outputs.at("glsl");
  return o;
}

}  // namespace

// NIST's examples (FIPS 180-2, appendix B; the CAVS SHA256ShortMsg 8-bit message): the
// keys are SHA-256, whichever implementation computes them (OpenSSL's libcrypto).
TEST(Sha256, KnownVectors) {
  EXPECT_EQ(sha256Hex("\xd3"), "28969cdfa74a12c82f3bad960b0b000aca2ac329deea5c2328ebc6f2ba9802c1");
  EXPECT_EQ(sha256Hex("abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnopjklmnopqklmnopqrlmnopqrsmnop"
                      "qrstnopqrstu"),
            "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
  EXPECT_EQ(sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  // 56 bytes: the padding spills into a second block.
  EXPECT_EQ(sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  std::string million(1000000, 'a');
  EXPECT_EQ(sha256Hex(million), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  // Fed in pieces: the same digest.
  Sha256 h;
  for (size_t i = 0; i < million.size(); i += 777) h.update(std::string_view(million).substr(i, 777));
  EXPECT_EQ(h.hex(), sha256Hex(million));
  // A field is its length (8 bytes, little-endian) and its bytes.
  EXPECT_EQ(Sha256().field("abc").hex(), sha256Hex(std::string("\x03\0\0\0\0\0\0\0abc", 11)));
}

// An entry carries the SHA-256 of its key and body: any changed, missing or added byte, and
// the right bytes under another key, are refused.
TEST(CacheEntry, VerifiedOnOpen) {
  const std::string key(64, 'a'), other(64, 'b'), body = "shadergen-variant-cache 3\ncost 7\nrules x\n";
  const std::string entry = sealEntry(key, body);
  std::string why;
  ASSERT_EQ(openEntry(key, entry, why), body);
  for (size_t i = 0; i < entry.size(); i += 7) {
    std::string flipped = entry;
    flipped[i] ^= 0x20;
    EXPECT_FALSE(openEntry(key, flipped, why)) << i;
  }
  for (size_t n = 0; n < entry.size(); n += 5) EXPECT_FALSE(openEntry(key, entry.substr(0, n), why)) << n;
  EXPECT_FALSE(openEntry(key, entry + "x", why));
  EXPECT_FALSE(openEntry(other, entry, why));
  EXPECT_NE(why.find("does not match"), std::string::npos) << why;
  EXPECT_FALSE(openEntry(key, body, why));  // an entry of the earlier layout: a miss
}

TEST(CacheUrl, CredentialsOnlyFromTheEnvironmentAndNeverShown) {
  EXPECT_EQ(redactUrl("http://user:pw@host:8080/c/x"), "http://***@host:8080/c/x");
  EXPECT_EQ(redactUrl("https://host/c@d"), "https://host/c@d");
  EXPECT_EQ(redactUrl("http://host:1/c"), "http://host:1/c");
  unsetenv("SHADERGEN_CACHE_URL");
  EXPECT_EQ(chooseCacheUrl("", "http://m/c"), "http://m/c");
  EXPECT_EQ(chooseCacheUrl("http://f/c", "http://m/c"), "http://f/c");
  setenv("SHADERGEN_CACHE_URL", "http://u:secret@e/c", 1);
  EXPECT_EQ(chooseCacheUrl("", "http://m/c"), "http://u:secret@e/c");  // the environment may hold them
  EXPECT_EQ(chooseCacheUrl("http://f/c", ""), "http://f/c");            // the flag wins
  unsetenv("SHADERGEN_CACHE_URL");
  try {
    chooseCacheUrl("http://u:secret@f/c", "");
    ADD_FAILURE() << "accepted credentials on the command line";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).find("secret"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("SHADERGEN_CACHE_AUTH"), std::string::npos) << e.what();
  }
  // In a manifest (a file in the repository): refused, naming the line without quoting it.
  auto d = errorOf([] {
    loadManifestText("rules: r.yaml\nrigs:\n  face: f.rig.yaml\npasses:\n  color: c.frag\n"
                     "cache_url: http://u:secret@m/c\n",
                     "m.yaml");
  });
  EXPECT_EQ(d.loc.line, 0);
  EXPECT_NE(d.message.find("line 6: 'cache_url'"), std::string::npos) << d.message;
  EXPECT_EQ(d.message.find("secret"), std::string::npos) << d.message;
  EXPECT_NE(d.message.find("http://***@m/c"), std::string::npos) << d.message;
}

// A local cache entry damaged on disk is reported, rebuilt to the same bytes and rewritten.
TEST(Build, DamagedEntriesAreReportedAndRebuilt) {
  auto dir = freshDir("dmg");
  Manifest m = loadManifest(smallManifest(dir).string());
  std::vector<Variant> variants = expandVariants(m);
  std::vector<std::string> warnings;
  BuildOptions bo;
  bo.cacheDir = (dir / "cache").string();
  bo.warn = [&](const std::string& w) { warnings.push_back(w); };
  BuildReport cold = buildVariants(m, variants, bo);
  fs::path victim = fs::path(bo.cacheDir) / cold.variants[0].key.substr(0, 2) / cold.variants[0].key;
  std::string bytes = readAll(victim);
  bytes[bytes.size() / 2] ^= 1;
  writeText(victim, bytes);
  BuildReport warm = buildVariants(m, variants, bo);
  EXPECT_EQ(warm.generated, 1u);
  EXPECT_EQ(warm.cache.rejected, 1u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find(cold.variants[0].key + " rejected"), std::string::npos) << warnings[0];
  EXPECT_EQ(filesOf(warm), filesOf(cold));
  EXPECT_EQ(buildVariants(m, variants, bo).cached, variants.size());  // rewritten
}

TEST(Manifest, ValidationSettings) {
  const std::string head = "rules: r.yaml\nrigs:\n  face: f.rig.yaml\npasses:\n  color: c.frag\n";
  Manifest m = loadManifestText(head + "validate: { mesh: limb, poses: 3, seed: 9, time: [0, 0.5], tolerance_abs: 1e-5, "
                                       "cross_check: true, device: llvmpipe }\ncache_url: http://h/c\n",
                                "m.yaml");
  EXPECT_TRUE(m.validate.enabled);
  EXPECT_EQ(m.validate.mesh, "limb");
  EXPECT_EQ(m.validate.poses, 3);
  EXPECT_EQ(m.validate.seed, 9u);
  EXPECT_EQ(m.validate.times, (std::vector<double>{0, 0.5}));
  EXPECT_EQ(m.validate.toleranceAbs, 1e-5);
  EXPECT_TRUE(m.validate.crossCheck);
  EXPECT_EQ(m.validate.device, "llvmpipe");
  EXPECT_EQ(m.cacheUrl, "http://h/c");
  EXPECT_FALSE(loadManifestText(head + "validate: false\n", "m.yaml").validate.enabled);
  EXPECT_FALSE(loadManifestText(head, "m.yaml").validate.enabled);
  auto fail = [&](const std::string& text) {
    return errorOf([&] { loadManifestText(head + text, "m.yaml"); });
  };
  auto d = fail("validate: { poses: 0 }\n");
  EXPECT_NE(d.message.find("1..100"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.line, 6);
  d = fail("validate: { mesh: cube }\n");
  EXPECT_NE(d.message.find("unknown mesh 'cube'"), std::string::npos) << d.message;
  d = fail("validate: { tolerance_rel: -1 }\n");
  EXPECT_NE(d.message.find("not a finite non-negative number"), std::string::npos) << d.message;
  d = fail("validate: { posse: 2 }\n");
  EXPECT_NE(d.message.find("posse"), std::string::npos) << d.message;
}

TEST(Manifest, ProductMinusExclusionsInOrder) {
  auto dir = freshDir("m");
  Manifest m = loadManifest(smallManifest(dir).string());
  std::vector<Variant> v = expandVariants(m);
  // rig(2) x pass(3) x morph(2) x influences(2) = 24, minus body x m2 (3 passes x 2) = 18.
  ASSERT_EQ(v.size(), 18u);
  EXPECT_EQ(v.front().name, "face-color-morph_targets2-influences4");
  EXPECT_EQ(v[1].name, "face-color-morph_targets2-influences1");
  EXPECT_EQ(v.back().name, "body-shadow-morph_targets0-influences1");
  std::set<std::string> names;
  for (const auto& x : v) {
    names.insert(x.name);
    EXPECT_FALSE(x.rig->name == "body" && x.params.at("morph_targets") == 2) << x.name;
  }
  EXPECT_EQ(names.size(), v.size());
}

TEST(Manifest, ErrorsAreLocated) {
  auto dir = freshDir("e");
  auto fail = [&](const std::string& text) {
    writeText(dir / "bad.yaml", text);
    return errorOf([&] { expandVariants(loadManifest((dir / "bad.yaml").string())); });
  };
  const std::string head = "rules: r.yaml\nrigs:\n  face: f.rig.yaml\npasses:\n  color: c.frag\n";
  auto d = fail(head + "axes:\n  rig: [face, bdy]\n");
  EXPECT_NE(d.message.find("no rig named 'bdy'"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.line, 7);
  d = fail(head + "outptu: x\n");
  EXPECT_NE(d.message.find("outptu"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.line, 6);
  d = fail(head + "axes:\n  influences: [4, four]\n");
  EXPECT_NE(d.message.find("'four' is not a non-negative integer"), std::string::npos) << d.message;
  d = fail(head + "axes:\n  influences: [4, 4]\n");
  EXPECT_NE(d.message.find("twice"), std::string::npos) << d.message;
  d = fail(head + "axes:\n  influences: [4]\nexclude:\n  - { influences: 2 }\n");
  EXPECT_NE(d.message.find("no value '2'"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.line, 9);
  d = fail(head + "axes:\n  influences: [4]\nexclude:\n  - { influences: 4 }\n");
  EXPECT_NE(d.message.find("no variant"), std::string::npos) << d.message;
  d = fail(head + "axes:\n  influences: [4, 1]\nname: \"{rig}\"\n");
  EXPECT_NE(d.message.find("both named 'face'"), std::string::npos) << d.message;
  d = fail(head + "name: \"{rig}/../x\"\n");
  EXPECT_NE(d.message.find("not a safe file name"), std::string::npos) << d.message;
  d = fail(head + "name: \"{lod}\"\n");
  EXPECT_NE(d.message.find("unknown axis '{lod}'"), std::string::npos) << d.message;
  // The map form of a rig: its keys and its path are checked where they are written.
  d = fail("rules: r.yaml\nrigs:\n  face: { path: f.rig.yaml, bna: [x] }\npasses:\n  color: c.frag\n");
  EXPECT_NE(d.message.find("bna"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.line, 3);
  d = fail("rules: r.yaml\nrigs:\n  face: { ban: [x] }\npasses:\n  color: c.frag\n");
  EXPECT_NE(d.message.find("rig 'face' needs 'path'"), std::string::npos) << d.message;
  d = fail("rigs: [a, b]\n");
  EXPECT_EQ(d.loc.file, (dir / "bad.yaml").string());
  EXPECT_GT(d.loc.line, 0);
}

// Every output equals what generate() makes for the same rig, parameters and pass.
TEST(Build, OutputsAreGeneratesBytes) {
  auto dir = freshDir("b");
  Manifest m = loadManifest(smallManifest(dir).string());
  std::vector<Variant> variants = expandVariants(m);
  BuildOptions bo;
  bo.jobs = 2;
  BuildReport r = buildVariants(m, variants, bo);
  ASSERT_EQ(r.failed, 0u);
  EXPECT_EQ(r.generated, variants.size());
  auto files = filesOf(r);
  std::map<std::string, std::set<std::string>> pathsOfModule;  // SPIR-V bytes -> output paths
  for (const auto& b : r.variants) {
    const Variant& v = *b.variant;
    GenerateResult g = generate(generateCommandOf(m, b));
    EXPECT_EQ(files.at(b.outputs.at("glsl")), g.glsl.text) << v.name;
    std::string spv(reinterpret_cast<const char*>(g.spirv.words.data()), g.spirv.words.size() * 4);
    EXPECT_EQ(files.count(b.outputs.at("spv")) ? files.at(b.outputs.at("spv")) : b.spirv, spv) << v.name;
    EXPECT_EQ(b.spirv, spv) << v.name;
    EXPECT_EQ(files.at(b.outputs.at("reflection")), reflectionJson(g.in.rig, g.glsl, g.spirv)) << v.name;
    EXPECT_EQ(b.cost, g.plan.cost) << v.name;
    pathsOfModule[spv].insert(b.outputs.at("spv"));
  }
  // Identical SPIR-V is one file (the depth and shadow passes feed no varyings: at least
  // those pairs), different SPIR-V different files.
  std::set<std::string> allPaths;
  for (const auto& [bytes, paths] : pathsOfModule) {
    EXPECT_EQ(paths.size(), 1u);
    allPaths.insert(paths.begin(), paths.end());
  }
  EXPECT_EQ(allPaths.size(), pathsOfModule.size());
  EXPECT_EQ(r.sharedSpirv, variants.size() - pathsOfModule.size());
  EXPECT_GE(r.sharedSpirv, 6u);
  size_t spirvFiles = 0;
  for (const auto& [path, bytes] : files) spirvFiles += path.find("/spirv/") != std::string::npos;
  EXPECT_EQ(spirvFiles, pathsOfModule.size());
  // The index and the depfiles.
  ASSERT_FALSE(r.indexPath.empty());
  const std::string& index = files.at(r.indexPath);
  EXPECT_NE(index.find("\"name\": \"face-color-morph_targets2-influences4\""), std::string::npos);
  EXPECT_NE(index.find("\"cost\": " + std::to_string(r.variants[0].cost)), std::string::npos);
  const std::string& dep = files.at((fs::path(m.outputDir) / "face-color-morph_targets2-influences4.d").string());
  EXPECT_NE(dep.find("face.rig.yaml"), std::string::npos);
  EXPECT_NE(dep.find("standard.yaml"), std::string::npos);  // included by the rules file
  EXPECT_EQ(dep.find("body.rig.yaml"), std::string::npos);
  EXPECT_NE(files.at(r.indexPath + ".d").find("body.rig.yaml"), std::string::npos);
}

TEST(Build, CacheRegeneratesOnlyWhatChanged) {
  auto dir = freshDir("c");
  Manifest m = loadManifest(smallManifest(dir).string());
  std::vector<Variant> variants = expandVariants(m);
  BuildOptions bo;
  bo.cacheDir = (dir / "cache").string();
  BuildReport cold = buildVariants(m, variants, bo);
  ASSERT_EQ(cold.generated, variants.size());
  BuildReport warm = buildVariants(m, variants, bo);
  EXPECT_EQ(warm.cached, variants.size());
  EXPECT_EQ(warm.generated, 0u);
  EXPECT_EQ(filesOf(warm), filesOf(cold));
  // Editing the face rig (bytes, not meaning) regenerates the face's variants only.
  { std::ofstream(dir / "face.rig.yaml", std::ios::app) << "# edited\n"; }
  BuildReport edited = buildVariants(m, variants, bo);
  size_t face = 0;
  for (const auto& v : variants) face += v.rig->name == "face";
  EXPECT_EQ(edited.generated, face);
  EXPECT_EQ(edited.cached, variants.size() - face);
  EXPECT_EQ(filesOf(edited), filesOf(cold));  // a comment changes no output
  // A damaged entry is a miss, regenerated to the same bytes.
  size_t damaged = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir / "cache"))
    if (e.is_regular_file() && damaged++ < 3) fs::resize_file(e.path(), fs::file_size(e.path()) / 2);
  BuildReport repaired = buildVariants(m, variants, bo);
  EXPECT_EQ(repaired.generated + repaired.cached, variants.size());
  EXPECT_LE(repaired.generated, 3u);  // stale entries of the unedited face may be among the damaged
  auto same = filesOf(cold);
  for (const auto& [path, bytes] : filesOf(repaired)) EXPECT_TRUE(same[path] == bytes) << path;
  // A different option is a different key.
  Manifest opt = m;
  opt.optimize = true;
  EXPECT_EQ(buildVariants(opt, expandVariants(opt), bo).generated, variants.size());
}

// emit: hlsl, msl (docs/hlsl-msl.md): each variant's .hlsl and .metal are generate()'s text
// with the manifest's options, cached like the other outputs; the options are in the key.
TEST(Build, HlslAndMslAreGeneratesTextsAndCached) {
  auto dir = freshDir("x");
  Manifest m = loadManifest(
      smallManifest(dir, "emit: [spv, hlsl, msl, reflection]\nhlsl_shader_model: \"6.0\"\nmsl_platform: ios\n").string());
  EXPECT_EQ(m.hlsl.shaderModel, 60);
  EXPECT_EQ(m.msl.platform, MslPlatform::IOS);
  std::vector<Variant> variants = expandVariants(m);
  BuildOptions bo;
  bo.cacheDir = (dir / "cache").string();
  BuildReport r = buildVariants(m, variants, bo);
  ASSERT_EQ(r.failed, 0u);
  auto files = filesOf(r);
  for (const auto& b : r.variants) {
    GenerateOptions o;
    o.rigPath = b.variant->rig->path;
    o.fragmentPath = b.variant->pass->fragment;
    o.rulesPaths = m.rules;
    o.rigParams = b.variant->params;
    o.outputName = (fs::path(m.outputDir) / (b.variant->name + ".vert")).string();
    o.hlsl = HlslOptions{60};
    o.msl = MslOptions{2, 0, MslPlatform::IOS};
    GenerateResult g = generate(o);
    EXPECT_EQ(b.outputs.at("hlsl"), (fs::path(m.outputDir) / (b.variant->name + ".hlsl")).string());
    EXPECT_EQ(files.at(b.outputs.at("hlsl")), g.hlsl->text) << b.variant->name;
    EXPECT_EQ(files.at(b.outputs.at("msl")), g.msl->text) << b.variant->name;
    EXPECT_EQ(files.at(b.outputs.at("reflection")), reflectionOf(g)) << b.variant->name;
    EXPECT_EQ(b.outputs.count("glsl"), 0u);
  }
  EXPECT_NE(files.at(r.indexPath).find("\"hlsl_shader_model\": \"6.0\""), std::string::npos);
  EXPECT_NE(files.at(r.indexPath).find(".metal\""), std::string::npos);
  BuildReport warm = buildVariants(m, variants, bo);
  EXPECT_EQ(warm.cached, variants.size());
  EXPECT_EQ(filesOf(warm), files);
  Manifest sm51 = m;
  sm51.hlsl.shaderModel = 51;  // another shader model: another key
  EXPECT_EQ(buildVariants(sm51, expandVariants(sm51), bo).generated, variants.size());
}

TEST(Manifest, TranslationOptionsAreChecked) {
  auto dir = freshDir("xo");
  auto errorFor = [&](const std::string& extra) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    return errorOf([&] { loadManifest(smallManifest(dir, extra).string()); });
  };
  EXPECT_NE(errorFor("emit: [hlsl]\nhlsl_shader_model: \"4.0\"\n").message.find("unsupported shader model '4.0'"),
            std::string::npos);
  EXPECT_NE(errorFor("emit: [msl]\nmsl_version: \"2.7\"\n").message.find("unsupported Metal Shading Language version"),
            std::string::npos);
  EXPECT_NE(errorFor("emit: [spv]\nhlsl_shader_model: \"6.0\"\n").message.find("'emit' has no hlsl"), std::string::npos);
  EXPECT_NE(errorFor("emit: [hlsl, dxil]\n").message.find("unknown emit kind 'dxil'"), std::string::npos);
}

TEST(Build, SameBytesWhateverTheThreadCount) {
  auto dir = freshDir("t");
  Manifest m = loadManifest(smallManifest(dir).string());
  std::vector<Variant> variants = expandVariants(m);
  BuildOptions one, many;
  one.jobs = 1;
  many.jobs = 5;
  EXPECT_EQ(filesOf(buildVariants(m, variants, one)), filesOf(buildVariants(m, variants, many)));
}

TEST(Build, AFailingVariantIsReportedAndLeavesTheIndexOut) {
  auto dir = freshDir("f");
  // Eight influences need a second weights/joints stream the Dawn rigs do not have.
  Manifest m = loadManifest(smallManifest(dir, "").string());
  m.axes.back().values.push_back("8");
  std::vector<Variant> variants = expandVariants(m);
  BuildReport r = buildVariants(m, variants, {});
  size_t eight = 0;
  for (const auto& b : r.variants) {
    bool isEight = b.variant->params.at("influences") == 8;
    eight += isEight;
    EXPECT_EQ(b.ok, !isEight) << b.variant->name;
    if (isEight) {
      ASSERT_FALSE(b.errors.empty());
      EXPECT_FALSE(b.errors.front().loc.file.empty()) << b.errors.front().message;
    }
  }
  EXPECT_EQ(r.failed, eight);
  EXPECT_TRUE(r.indexPath.empty());
  for (const auto& f : r.files) EXPECT_EQ(f.path.find("index.json"), std::string::npos) << f.path;
}

TEST(Build, MissingSharedInputIsALocatedError) {
  auto dir = freshDir("s");
  Manifest m = loadManifest(smallManifest(dir).string());
  fs::remove(dir / "body.rig.yaml");
  auto d = errorOf([&] { buildVariants(m, expandVariants(m), {}); });
  EXPECT_NE(d.loc.file.find("body.rig.yaml"), std::string::npos) << d.loc.file << ": " << d.message;
}

// A rig storing its frame both as floats and as octahedral codes: a build chooses the form
// as generate does (under the H200 profile, the codes), and `max_error` takes the codes out
// as --max-error does (then the floats) — byte for byte what generate() writes each time.
TEST(Build, StoredFormsAndErrorBudgetsAreGeneratesChoices) {
  const std::string data = std::string(SG_SOURCE_DIR) + "/tests/validate/data/";
  for (const std::string budget : {"", "max_error: { vertex.normal: 0.001deg }\n"}) {
    SCOPED_TRACE(budget);
    auto dir = freshDir(budget.empty() ? "forms" : "budget");
    writeText(dir / "m.yaml", "output: out\nrules: " + std::string(SG_SOURCE_DIR) + "/rules/standard.yaml\n" +
                                  "device_profile: " + SG_SOURCE_DIR + "/devices/nvidia-h200.yaml\n" + budget +
                                  "rigs:\n  limb: " + data + "octahedral_or_float.rig.yaml\n"
                                  "passes:\n  world: " + data + "world.frag\n");
    Manifest m = loadManifest((dir / "m.yaml").string());
    std::vector<Variant> variants = expandVariants(m);
    BuildReport r = buildVariants(m, variants, BuildOptions{});
    ASSERT_EQ(r.failed, 0u);
    ASSERT_EQ(r.variants.size(), 1u);
    GenerateOptions o;
    o.rigPath = data + "octahedral_or_float.rig.yaml";
    o.fragmentPath = data + "world.frag";
    o.rulesPaths = m.rules;
    o.deviceProfilePath = m.deviceProfile;
    o.maxError = m.maxError;
    o.outputName = r.variants[0].outputs.at("glsl");
    GenerateResult g = generate(o);
    const std::string glsl = filesOf(r).at(r.variants[0].outputs.at("glsl"));
    EXPECT_EQ(glsl, g.glsl.text);
    EXPECT_EQ(glsl.find("vertex_normal_from_octahedral") != std::string::npos, budget.empty());
    // The index records the budgets the outputs were made under.
    EXPECT_EQ(filesOf(r).at(r.indexPath).find("\"max_error\": {\"vertex.normal\": 0.001}") != std::string::npos,
              !budget.empty());
  }
}

TEST(Manifest, ErrorBudgetsAreChecked) {
  auto dir = freshDir("mb");
  const std::string head = "rules: r.yaml\nrigs:\n  face: f.rig.yaml\npasses:\n  color: c.frag\n";
  auto fail = [&](const std::string& text) {
    writeText(dir / "bad.yaml", head + text);
    return errorOf([&] { loadManifest((dir / "bad.yaml").string()); });
  };
  auto d = fail("max_error: { vertex.normal: 0.1 }\n");
  EXPECT_NE(d.message.find("expected a positive angle in deg or rad"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.line, 6);
  EXPECT_EQ(d.loc.col, 29);
  d = fail("max_error: { world.normal: 1deg }\n");
  EXPECT_NE(d.message.find("no encoding stores 'world.normal'"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.col, 14);
  d = fail("max_error: { vertex.position: 1deg }\n");
  EXPECT_NE(d.message.find("a positive fraction of the bounds diagonal"), std::string::npos) << d.message;
  EXPECT_EQ(loadManifestText(head + "max_error: { vertex.position: 1e-4, vertex.normal: 0.1rad }\n", "m.yaml").maxError,
            (std::map<std::string, double>{{"vertex.normal", glm::degrees(0.1)}, {"vertex.position", 1e-4}}));
}

// The workload a variant is priced for (BuildOptions::workloads, measured by the CLI from the
// manifest's `mesh:`): with a profile it is recorded in the reflection, as generate records it,
// and a different workload is a different cache key; an unknown mesh is a located error.
TEST(Build, TheWorkloadIsRecordedAndKeyed) {
  auto dir = freshDir("workload");
  const std::string data = std::string(SG_SOURCE_DIR) + "/tests/validate/data/";
  writeText(dir / "m.yaml", "output: out\nrules: " + std::string(SG_SOURCE_DIR) + "/rules/standard.yaml\n" +
                                "device_profile: " + SG_SOURCE_DIR + "/devices/nvidia-h200.yaml\nmesh: dawn\n" +
                                "rigs:\n  limb: " + data + "limb8.rig.yaml\npasses:\n  world: " + data + "world.frag\n");
  Manifest m = loadManifest((dir / "m.yaml").string());
  EXPECT_EQ(m.mesh, "dawn");
  std::vector<Variant> variants = expandVariants(m);
  ASSERT_EQ(variants.size(), 1u);
  BuildOptions bo;
  bo.workloads[variants[0].name] = Workload{180000, 2.5, -1, 2.1, "procedural mesh 'dawn'"};
  BuildReport r = buildVariants(m, variants, bo);
  ASSERT_EQ(r.failed, 0u);
  const std::string reflection = filesOf(r).at(r.variants[0].outputs.at("reflection"));
  GenerateOptions o;
  o.rigPath = data + "limb8.rig.yaml";
  o.fragmentPath = data + "world.frag";
  o.rulesPaths = m.rules;
  o.deviceProfilePath = m.deviceProfile;
  o.workload = bo.workloads.begin()->second;
  o.outputName = r.variants[0].outputs.at("glsl");
  EXPECT_EQ(reflection, reflectionOf(generate(o)));
  EXPECT_NE(reflection.find("\"workload\": {\"vertices_per_draw\": 180000, \"joints_per_warp\": 2.5"), std::string::npos)
      << reflection;
  BuildReport unknown = buildVariants(m, variants, BuildOptions{});
  EXPECT_NE(unknown.variants[0].key, r.variants[0].key);
  bo.workloads.begin()->second.jointsPerWarp = 3;
  EXPECT_NE(buildVariants(m, variants, bo).variants[0].key, r.variants[0].key);

  writeText(dir / "bad.yaml", "rules: r.yaml\nrigs:\n  face: f.rig.yaml\npasses:\n  color: c.frag\nmesh: cube\n");
  const auto d = errorOf([&] { loadManifest((dir / "bad.yaml").string()); });
  EXPECT_NE(d.message.find("unknown mesh 'cube'"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.line, 6);
}

// `device_profile: [a, b]` (docs/variants.md, "Device profiles"): every variant is the portable
// plan generate() writes with --device-profile a --device-profile b, which on the head is neither
// device's own choice; index.json lists the profiles; each profile's bytes are in the key; an empty
// list or a profile listed twice is a located error.
TEST(Build, AListOfProfilesBuildsThePortablePlan) {
  auto dir = freshDir("portable");
  fs::copy_file(std::string(SG_SOURCE_DIR) + "/devices/nvidia-h200-raster.yaml", dir / "gpu.yaml");
  fs::copy_file(std::string(SG_SOURCE_DIR) + "/devices/llvmpipe-2core.yaml", dir / "cpu.yaml");
  auto manifest = [&](const std::string& profiles) {
    writeText(dir / "m.yaml", "output: out\nrules: " + kDawn + "rules.yaml\n" + profiles + "mesh: head\n" +
                                  "rigs:\n  face: " + kDawn + "face.rig.yaml\npasses:\n  color: " + kDawn + "face.frag\n" +
                                  "axes:\n  influences: [4, 2]\n");
    return loadManifest((dir / "m.yaml").string());
  };
  Manifest m = manifest("device_profile:\n  - gpu.yaml\n  - cpu.yaml\n");
  EXPECT_EQ(m.deviceProfile, (dir / "gpu.yaml").string());
  EXPECT_EQ(m.portableProfiles, std::vector<std::string>{(dir / "cpu.yaml").string()});
  const std::vector<Variant> variants = expandVariants(m);
  ASSERT_EQ(variants.size(), 2u);
  BuildOptions bo;
  const Workload head{2009, 12.23, -1, 2.071, "procedural mesh 'head'"};
  for (const auto& v : variants) bo.workloads[v.name] = head;
  BuildReport r = buildVariants(m, variants, bo);
  ASSERT_EQ(r.failed, 0u);
  const auto files = filesOf(r);
  for (const auto& b : r.variants) {
    GenerateOptions o = generateCommandOf(m, b);
    o.deviceProfilePath = (dir / "gpu.yaml").string();
    o.portableProfilePaths = {(dir / "cpu.yaml").string()};
    o.workload = head;
    const GenerateResult portable = generate(o);
    EXPECT_EQ(files.at(b.outputs.at("glsl")), portable.glsl.text) << b.variant->name;
    EXPECT_EQ(files.at(b.outputs.at("reflection")), reflectionOf(portable)) << b.variant->name;
    // Neither device's own plan: the choice is the compromise, not the first profile's.
    for (const std::string& alone : {o.deviceProfilePath, o.portableProfilePaths[0]}) {
      GenerateOptions one = o;
      one.deviceProfilePath = alone;
      one.portableProfilePaths.clear();
      if (b.variant->params.at("influences") == 4) EXPECT_NE(generate(one).glsl.text, portable.glsl.text) << alone;
    }
  }
  const std::string& index = files.at(r.indexPath);
  EXPECT_NE(index.find("\"device_profiles\": [\"" + (dir / "gpu.yaml").string() + "\", \"" + (dir / "cpu.yaml").string() + "\"]"),
            std::string::npos)
      << index;
  EXPECT_EQ(index.find("\"device_profile\""), std::string::npos);

  // One profile is another key; so is the second profile's content.
  Manifest single = manifest("device_profile: gpu.yaml\n");
  EXPECT_TRUE(single.portableProfiles.empty());
  const std::string singleKey = buildVariants(single, expandVariants(single), bo).variants[0].key;
  EXPECT_NE(singleKey, r.variants[0].key);
  Manifest listOfOne = manifest("device_profile: [gpu.yaml]\n");  // the single profile, key and all
  EXPECT_TRUE(listOfOne.portableProfiles.empty());
  EXPECT_EQ(buildVariants(listOfOne, expandVariants(listOfOne), bo).variants[0].key, singleKey);
  writeText(dir / "cpu.yaml", readAll(dir / "cpu.yaml") + "# edited\n");
  m = manifest("device_profile: [gpu.yaml, cpu.yaml]\n");
  EXPECT_NE(buildVariants(m, expandVariants(m), bo).variants[0].key, r.variants[0].key);

  Diagnostic d = errorOf([&] { manifest("device_profile: []\n"); });
  EXPECT_NE(d.message.find("'device_profile' is an empty list"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.line, 3);
  d = errorOf([&] { manifest("device_profile:\n  - gpu.yaml\n  - ./gpu.yaml\n"); });
  EXPECT_NE(d.message.find("gpu.yaml' is listed twice"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.line, 5);
}

// A rig's `ban:` (docs/variants.md, "Pinning a plan"): its variants are generate()'s with those
// --bans, byte for byte; the bans are in the cache key (the rig's variants regenerate, the
// others stay cached); a misspelt rule name is an error at the ban's line.
TEST(Build, ARigsBansPinItsPlansAndAreInTheKey) {
  auto dir = freshDir("ban");
  const fs::path plain = smallManifest(dir);
  const std::string text = readAll(plain);
  const std::string rigLine = "  face: face.rig.yaml\n";
  ASSERT_NE(text.find(rigLine), std::string::npos);
  auto withFace = [&](const std::string& face) {
    std::string t = text;
    t.replace(t.find(rigLine), rigLine.size(), face);
    writeText(dir / "pinned.yaml", t);
    return loadManifest((dir / "pinned.yaml").string());
  };
  const std::vector<std::string> bans = {"skin_matrix_blend", "skin_matrix_blend_buffer_palette"};
  Manifest pinned = withFace("  face:\n    path: face.rig.yaml\n    ban: [skin_matrix_blend, skin_matrix_blend_buffer_palette]\n");
  ASSERT_EQ(pinned.rigs[0].name, "face");
  EXPECT_EQ(pinned.rigs[0].bans, bans);
  EXPECT_TRUE(pinned.rigs[1].bans.empty());

  BuildOptions bo;
  bo.cacheDir = (dir / "cache").string();
  Manifest m = loadManifest(plain.string());
  BuildReport before = buildVariants(m, expandVariants(m), bo);
  ASSERT_EQ(before.failed, 0u);
  const std::vector<Variant> variants = expandVariants(pinned);
  BuildReport r = buildVariants(pinned, variants, bo);
  ASSERT_EQ(r.failed, 0u);
  const auto files = filesOf(r);
  size_t face = 0, blendsReplaced = 0;
  for (const auto& b : r.variants) {
    const Variant& v = *b.variant;
    GenerateOptions o = generateCommandOf(pinned, b);
    if (v.rig->name == "face") {
      ++face;
      o.bannedRules = bans;
      for (const auto& rule : b.rules) EXPECT_TRUE(rule != bans[0] && rule != bans[1]) << v.name << ": " << rule;
      blendsReplaced += std::count(b.rules.begin(), b.rules.end(), "skin_matrix_blend_buffered_influences");
    }
    EXPECT_EQ(files.at(b.outputs.at("glsl")), generate(o).glsl.text) << v.name;
  }
  // The 4-influence face variants blend with the influences from buffers instead.
  EXPECT_GT(blendsReplaced, 0u);
  // index.json says which variants were pinned, and by what; the others carry no "bans".
  const std::string& index = files.at(r.indexPath);
  const std::string listed = "\"bans\": [\"skin_matrix_blend\", \"skin_matrix_blend_buffer_palette\"]";
  size_t n = 0;
  for (size_t at = index.find(listed); at != std::string::npos; at = index.find(listed, at + 1)) ++n;
  EXPECT_EQ(n, face);
  EXPECT_EQ(index.find("\"bans\""), index.find(listed));
  EXPECT_EQ(r.generated, face);
  EXPECT_EQ(r.cached, variants.size() - face);

  const Diagnostic d = errorOf([&] {
    Manifest bad = withFace("  face:\n    path: face.rig.yaml\n    ban: skin_matrix_blendd\n");
    buildVariants(bad, expandVariants(bad), BuildOptions{});
  });
  EXPECT_NE(d.message.find("rig 'face' bans 'skin_matrix_blendd': no rule of that name"), std::string::npos) << d.message;
  EXPECT_EQ(d.loc.file, (dir / "pinned.yaml").string());
  EXPECT_EQ(d.loc.line, 6);  // output, rules, rigs, face, path, ban
}
