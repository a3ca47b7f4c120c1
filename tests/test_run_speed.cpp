// Issue 33: the ci suite's time. `run --profile` says where it goes (per stage, per test), and the
// work shared between tests stays correct. No test here measures a time: each checks what the
// profile names and that its figures add up, or that a cache misses when an input changes
// (scripts/bench_speed.sh prints the timings).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <string>
#include <thread>

#include "harness/artefacts.h"
#include "harness/golden_store.h"
#include "harness/metrics_store.h"
#include "harness/runner.h"
#include "harness/sequence_store.h"
#include "harness/suite.h"
#include "harness/temporal_check.h"
#include "harness/timing_groups.h"
#include "harness/worker.h"
#include "image_io/image_io.h"
#include "kernel/hash.h"
#include "kernel/profile.h"
#include "kernel/program.h"
#include "metrics/display_transform.h"
#include "metrics/identical.h"
#include "renderers/environments/environment.h"
#include "renderers/mobile/cost_store.h"
#include "renderers/mobile/precompute_store.h"
#include "renderers/renderer.h"
#include "renderers/vulkan/shader_compiler.h"
#include "tests/furnace_store.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace iblcheck;
using namespace iblcheck::testutil;
using nlohmann::json;

// Its own namespace: the test programs of one group compile as unity batches (tests/CMakeLists.txt).
namespace test_run_speed {

namespace {

// Work the compiler cannot drop, so a stage has a duration above zero.
double spin(int n) {
    volatile double x = 0;
    for (int i = 0; i < n; ++i) x = x + 1e-9 * i;
    return x;
}

const char* kSuite = R"({
  "suite": "mini",
  "defaults": {"env": "constant:1",
               "baseline_tolerances": {"flip.mean": {"max": 0.001}, "ssim.mean": {"min": 0.999}},
               "reference_band": {"flip.mean": {"below": 0.2, "above": 0.1, "abs": 0.0}}},
  "tests": [{"scene": "furnace", "method": "mobile", "variants": [{}, {"storage": "astc_hdr"}]}]
})";

} // namespace

// Nested stages: the outer stage's clock stops while the inner one runs, so neither counts the
// other's time; off, nothing is recorded.
TEST(Profile, StagesNestExclusivelyAndRecordNothingWhenOff) {
    profile::enable(false);
    profile::take();
    {
        ProfileStage outer("outer");
        spin(100000);
    }
    EXPECT_TRUE(profile::take().empty());

    profile::enable(true);
    profile::take();
    const auto t0 = std::chrono::steady_clock::now();
    {
        ProfileStage outer("outer");
        spin(200000);
        {
            ProfileStage inner("inner");
            spin(200000);
        }
        spin(200000);
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const auto stages = profile::take();
    profile::enable(false);
    ASSERT_EQ(stages.size(), 2u);
    EXPECT_GT(stages.at("outer"), 0.0);
    EXPECT_GT(stages.at("inner"), 0.0);
    // Exclusive: together they are the block's wall time, never more (nested time counted twice was).
    EXPECT_LE(stages.at("outer") + stages.at("inner"), wall);
    EXPECT_TRUE(profile::take().empty()); // take() cleared them
}

// `run --profile` prints the stages of the issue and each test's results carry them; the stages
// of a test add up to (at most) its wall time. Without it the results have no "profile".
TEST(Profile, RunPrintsStagesAndEachTestRecordsThem) {
    FurnaceStore store("profile_run", kSuite);
    ASSERT_EQ(store.bless_all(), kExitPass);
    const fs::path out = store.dir / "out";
    std::string text;
    // An empty precompute store of its own, so the precompute and the ASTC encode run (and are stored).
    const std::string cmd = "IBLCHECK_PRECOMPUTE_CACHE=" + (store.dir / "precompute").string() + " " + built("iblcheck") +
                            " run --suite " + store.suite.string() + " --goldens " + store.goldens.string() +
                            " -q --jobs 1 --profile --out " + out.string();
    ASSERT_EQ(run_command(cmd, text), 0) << text;
    for (const char* stage :
         {"profile:", "precompute", "precompute_store", "astc_encode", "spirv_compile_or_cache", "pipeline_create", "shading",
          "counting_twin", "metrics", "files", "results_and_report", "slowest tests"})
        EXPECT_NE(text.find(stage), std::string::npos) << stage << " not in:\n" << text;
    const json results = json::parse(read_text(out / "results.json"));
    ASSERT_EQ(results["tests"].size(), 2u);
    for (const json& t : results["tests"]) {
        ASSERT_TRUE(t.contains("profile")) << t["name"];
        double sum = 0;
        for (const auto& [stage, s] : t["profile"].items()) sum += s.get<double>();
        EXPECT_GT(t["profile"].value("shading", 0.0), 0.0) << t["name"];
        EXPECT_GT(t["profile"].value("metrics", 0.0), 0.0) << t["name"];
        EXPECT_LE(sum, t["wall_s"].get<double>() + 1e-3) << t["name"]; // exclusive stages: no time counted twice
    }
    EXPECT_GT(results["tests"][1]["profile"].value("astc_encode", 0.0), 0.0); // the ASTC variant's encode is its own stage

    RunOptions o;
    o.suite = store.suite.string();
    o.goldens = store.goldens;
    o.quiet = true;
    const RunSummary plain = run_suite(o);
    EXPECT_FALSE(plain.results["tests"][0].contains("profile"));
}

// The ci suite's tests in batches that share a precompute, grouped by radiance chain: every test once,
// one precompute per batch and one chain per group, chains with the most tests first. The options that
// only change the shading (dominant_dir, normalization, shading=fragment, another scene) share the
// default's batch; those that only change how the chain is stored or what is added to it (storage,
// env_brdf=lut, diffuse=irradiance_cube) its chain; a mip curve, a layout or another environment
// neither.
TEST(SharedPrecompute, CiTestsAreBatchedByTheirPrecomputeAndChain) {
    const std::vector<TestCase> tests = load_suite("ci").tests;
    const std::vector<ChainBatches> chains = precompute_batches(tests);
    std::set<size_t> seen;
    std::set<std::string> chain_keys, precompute_keys;
    std::map<std::string, size_t> chain_of, batch_of;
    size_t before = tests.size(), batches = 0;
    for (size_t c = 0; c < chains.size(); ++c) {
        ASSERT_FALSE(chains[c].empty());
        const std::string chain = radiance_chain_share_key(tests[chains[c][0][0]].spec);
        size_t n = 0;
        for (const Batch& b : chains[c]) {
            ASSERT_FALSE(b.empty());
            const std::string full = precompute_share_key(tests[b[0]].spec);
            if (chain.empty()) { // the CPU truth: a test alone
                EXPECT_EQ(chains[c].size(), 1u);
                EXPECT_EQ(b.size(), 1u);
            } else {
                EXPECT_TRUE(precompute_keys.insert(full).second) << "two batches share " << full;
            }
            for (size_t i : b) {
                EXPECT_TRUE(seen.insert(i).second) << tests[i].name << " in two batches";
                EXPECT_EQ(radiance_chain_share_key(tests[i].spec), chain) << tests[i].name;
                EXPECT_EQ(precompute_share_key(tests[i].spec), full) << tests[i].name;
                chain_of[tests[i].name] = c;
                batch_of[tests[i].name] = batches;
            }
            n += b.size();
            ++batches;
        }
        if (!chain.empty()) {
            EXPECT_TRUE(chain_keys.insert(chain).second) << "two groups share " << chain;
        }
        EXPECT_LE(n, before); // the most tests first
        before = n;
    }
    EXPECT_EQ(seen.size(), tests.size());
    const std::string studio = "mobile.roughness_sweep.studio.default";
    for (const char* same :
         {"mobile.roughness_sweep.studio.dominant_dir=lagarde", "mobile.roughness_sweep.studio.normalization=ue4",
          "mobile.roughness_sweep.studio.shading=fragment", "mobile.sphere.studio.default"})
        EXPECT_EQ(batch_of.at(same), batch_of.at(studio)) << same;
    for (const char* same_chain :
         {"mobile.roughness_sweep.studio.storage=rgbm8", "mobile.roughness_sweep.studio.storage=astc_hdr",
          "mobile.roughness_sweep.studio.env_brdf=lut", "mobile.roughness_sweep.studio.diffuse=irradiance_cube"}) {
        EXPECT_EQ(chain_of.at(same_chain), chain_of.at(studio)) << same_chain;
        EXPECT_NE(batch_of.at(same_chain), batch_of.at(studio)) << same_chain;
    }
    for (const char* other :
         {"mobile.roughness_sweep.studio.mip_mapping=origin", "mobile.roughness_sweep.studio.env_layout=octahedral",
          "mobile.roughness_sweep.sky_sun.default", "sampled.roughness_sweep.studio.samples=64"})
        EXPECT_NE(chain_of.at(other), chain_of.at(studio)) << other;
    EXPECT_LT(precompute_keys.size(), tests.size());
    EXPECT_LT(chain_keys.size(), precompute_keys.size());
    std::printf("ci suite: %zu tests, %zu GPU precomputes from %zu radiance chains\n", tests.size(), precompute_keys.size(),
                chain_keys.size());
}

// A free worker takes the next batch of the chain it is on; else a chain no worker is on (in order);
// else it joins the chain with the most tests left. Handing out whole chains left one worker idle
// while the other ran the TSan slice's one chain (72.7 s against 50.6 s).
TEST(BatchQueue, AWorkerKeepsToItsChainAndJoinsAnotherOnlyWhenNoneIsFree) {
    BatchQueue q(std::vector<ChainBatches>{{{0, 1}, {2}, {3}, {4}}, {{5}, {6}}, {{7}}});
    EXPECT_EQ(q.next(0), Batch({0, 1})); // the first chain
    EXPECT_EQ(q.next(1), Batch({5}));    // a chain nobody is on
    EXPECT_EQ(q.next(0), Batch({2}));    // its own chain
    EXPECT_EQ(q.next(1), Batch({6}));
    EXPECT_EQ(q.next(1), Batch({7})); // its chain done: the one left that nobody is on
    EXPECT_EQ(q.next(1), Batch({3})); // none free: joins the first chain, the only one left
    EXPECT_EQ(q.next(0), Batch({4}));
    EXPECT_EQ(q.next(0), std::nullopt);
    EXPECT_EQ(q.next(1), std::nullopt);
    BatchQueue closed(std::vector<ChainBatches>{{{0}, {1}}});
    EXPECT_EQ(closed.next(0), Batch({0}));
    closed.close();
    EXPECT_EQ(closed.next(0), std::nullopt);
}

// Two workers on tests that interleave two precomputes, the first two tests sharing one: each is
// computed once (a render that reused it says so in its provenance). Handed out a test at a time,
// the two workers took the first two tests and both computed the first precompute.
TEST(SharedPrecompute, TwoWorkersComputeEachPrecomputeOnce) {
    const char* suite = R"({
  "suite": "mini",
  "defaults": {"env": "constant:1",
               "baseline_tolerances": {"flip.mean": {"max": 0.001}, "ssim.mean": {"min": 0.999}},
               "reference_band": {"flip.mean": {"below": 0.2, "above": 0.1, "abs": 0.0}}},
  "tests": [{"scene": "furnace", "method": "mobile", "variants": [{}, {"dominant_dir": "lagarde"}, {"storage": "rgbm8"},
            {"storage": "rgbm8", "dominant_dir": "lagarde"}, {"normalization": "ue4"}, {"storage": "rgbm8", "normalization": "ue4"}]}]
})";
    FurnaceStore store("shared_precompute", suite);
    ASSERT_EQ(store.bless_all(), kExitPass);
    RunOptions o;
    o.suite = store.suite.string();
    o.goldens = store.goldens;
    o.quiet = true;
    o.jobs = 2;
    setenv("IBLCHECK_PRECOMPUTE_CACHE", "0", 1); // the count is of this run's precomputes, none from disk
    const RunSummary s = run_suite(o);
    unsetenv("IBLCHECK_PRECOMPUTE_CACHE");
    ASSERT_EQ(s.results["tests"].size(), 6u);
    int computed = 0;
    for (const json& t : s.results["tests"]) {
        EXPECT_EQ(t["verdict"], "pass") << t["name"] << ": " << t["message"];
        computed += t["provenance"]["precompute_cached"].get<bool>() ? 0 : 1;
    }
    EXPECT_EQ(computed, 2);
}

// The session keeps its kCachedEntries most recently used entries (a nightly kept every precompute to
// its end): the oldest use goes first, a use counts as recent, an entry a render still holds lives on.
TEST(SharedPrecompute, SessionKeepsTheMostRecentlyUsedEntries) {
    GpuSession gpu;
    const size_t n = GpuSession::kCachedEntries;
    ASSERT_GE(n, 2u);
    for (size_t i = 0; i < n; ++i) gpu.store("k" + std::to_string(i), std::make_shared<int>(int(i)));
    std::shared_ptr<int> held = gpu.cached<int>("k1");
    for (size_t i = 0; i < n; ++i) // every other entry used after it: k1 is now the oldest use
        if (i != 1) {
            ASSERT_TRUE(gpu.cached<int>("k" + std::to_string(i)));
        }
    gpu.store("new", std::make_shared<int>(99));
    EXPECT_FALSE(gpu.cached<int>("k1"));
    EXPECT_EQ(*held, 1); // still the holder's
    for (const std::string key : {"k0", "new"}) EXPECT_TRUE(gpu.cached<int>(key)) << key;
    for (size_t i = 2; i < n; ++i) EXPECT_TRUE(gpu.cached<int>("k" + std::to_string(i))) << i;
    gpu.store("k0", std::make_shared<int>(7)); // replacing an entry evicts nothing
    EXPECT_EQ(*gpu.cached<int>("k0"), 7);
    for (size_t i = 2; i < n; ++i) EXPECT_TRUE(gpu.cached<int>("k" + std::to_string(i))) << i;
}

namespace {

// A render of `spec` with a fresh renderer (no session cache) and the precompute store at `store`
// ("0": off).
RenderResult fresh_render(const TestSpec& spec, const std::string& store) {
    setenv("IBLCHECK_PRECOMPUTE_CACHE", store.c_str(), 1);
    Renderer r;
    RenderResult out = r.render(spec);
    unsetenv("IBLCHECK_PRECOMPUTE_CACHE");
    return out;
}

TestSpec furnace_spec(const std::map<std::string, std::string>& options) {
    TestSpec s;
    s.scene = "furnace";
    s.method = "mobile";
    s.env = "studio";
    s.options.set("cube_size", "32");
    for (const auto& [k, v] : options) s.options.set(k, v);
    return s;
}

} // namespace

// Variants that differ only in how the prefiltered chain is stored, or in what is added to it (the
// DFG table, the irradiance cube), share one radiance chain in a session: its passes are measured
// once, so each variant reports the very timings of the first (a chain computed again is timed
// again), and each renders bit for bit as a session that computed the chain for it alone
// (encode_storage.comp: encoding the stored max(result, 0) is encoding the result).
TEST(SharedPrecompute, VariantsOfOneChainShareItAndRenderAsIfAlone) {
    auto prefilter_ms = [](const RenderResult& r) {
        for (const PassTiming& t : r.timings)
            if (t.name == "prefilter_ggx") return t.ms;
        return -1.0;
    };
    setenv("IBLCHECK_PRECOMPUTE_CACHE", "0", 1);
    Renderer shared;
    const RenderResult first = shared.render(furnace_spec({}));
    ASSERT_GT(prefilter_ms(first), 0.0);
    for (const auto& options : std::vector<std::map<std::string, std::string>>{{{"storage", "rgbm8"}},
                                                                               {{"storage", "r11g11b10"}},
                                                                               {{"storage", "rgba32f"}},
                                                                               {{"storage", "astc_ldr_rgbm"}},
                                                                               {{"env_brdf", "lut"}},
                                                                               {{"diffuse", "irradiance_cube"}}}) {
        const TestSpec spec = furnace_spec(options);
        const std::string what = spec.options.canonical();
        setenv("IBLCHECK_PRECOMPUTE_CACHE", "0", 1); // fresh_render unsets it
        const RenderResult r = shared.render(spec);
        EXPECT_FALSE(r.provenance["precompute_cached"].get<bool>()) << what; // its own precompute...
        EXPECT_EQ(prefilter_ms(r), prefilter_ms(first)) << what;             // ...from the shared chain
        EXPECT_TRUE(bit_identical(r.image, fresh_render(spec, "0").image)) << what;
    }
    unsetenv("IBLCHECK_PRECOMPUTE_CACHE");
}

// A precompute stored on disk renders bit-identically to one computed now, for every storage format
// the store holds (RGBA16F, RGBM8, R11G11B10, ASTC's decoded texels), a 2D layout, the LUT and the
// irradiance cube; a damaged entry is computed again, never read.
TEST(PrecomputeStore, StoredPrecomputeRendersBitIdenticallyAndADamagedEntryIsRecomputed) {
    const fs::path dir = temp_dir("precompute_store");
    for (const auto& options :
         std::vector<std::map<std::string, std::string>>{{},
                                                         {{"storage", "rgbm8"}},
                                                         {{"storage", "r11g11b10"}},
                                                         {{"storage", "astc_hdr"}},
                                                         {{"env_layout", "octahedral"}},
                                                         {{"env_brdf", "lut"}, {"diffuse", "irradiance_cube"}}}) {
        const TestSpec spec = furnace_spec(options);
        const std::string what = spec.options.canonical();
        const RenderResult computed = fresh_render(spec, "0");
        const RenderResult stored = fresh_render(spec, dir.string()); // computes it and stores it
        const RenderResult loaded = fresh_render(spec, dir.string()); // reads it
        EXPECT_FALSE(stored.provenance["precompute_cached"].get<bool>()) << what;
        EXPECT_TRUE(loaded.provenance["precompute_cached"].get<bool>()) << what;
        EXPECT_TRUE(bit_identical(computed.image, stored.image)) << what;
        EXPECT_TRUE(bit_identical(computed.image, loaded.image)) << what;
        EXPECT_EQ(computed.provenance["rgbm"], loaded.provenance["rgbm"]) << what;
        EXPECT_EQ(computed.provenance["texture"], loaded.provenance["texture"]) << what;
    }
    // Every entry cut in half: each render computes its precompute again, and renders the same.
    for (const auto& e : fs::directory_iterator(dir)) fs::resize_file(e.path(), fs::file_size(e.path()) / 2);
    const TestSpec spec = furnace_spec({{"storage", "rgbm8"}});
    const RenderResult again = fresh_render(spec, dir.string());
    EXPECT_FALSE(again.provenance["precompute_cached"].get<bool>());
    EXPECT_TRUE(bit_identical(again.image, fresh_render(spec, "0").image));
    fs::remove_all(dir);
}

// The entry's key changes with every input: the environment's pixels, a setting, a pass shader's
// include (not only the pass's own file), llvmpipe's CPU class; the same inputs give the same key.
TEST(PrecomputeStore, AChangedInputMisses) {
    GpuSession gpu;
    const Environment studio = load_environment("studio"), sky = load_environment("sky_sun");
    PrecomputeSettings s;
    const std::string key = precompute_store_key(gpu, studio, s);
    EXPECT_EQ(precompute_store_key(gpu, studio, s), key);
    EXPECT_NE(precompute_store_key(gpu, sky, s), key);
    PrecomputeSettings other = s;
    other.storage = "rgbm8";
    EXPECT_NE(precompute_store_key(gpu, studio, other), key);
    other = s;
    other.prefilter_samples = 128;
    EXPECT_NE(precompute_store_key(gpu, studio, other), key);

    // A copy of the shaders whose brdf.glsl (included by prefilter_ggx.comp) gained a comment.
    const fs::path shaders = temp_dir("precompute_store_shaders");
    fs::copy(vk::shader_dir(), shaders, fs::copy_options::recursive);
    std::ofstream(shaders / "brdf.glsl", std::ios::app) << "\n// edited\n";
    setenv("IBLCHECK_SHADER_DIR", shaders.c_str(), 1);
    const std::string edited = precompute_store_key(gpu, studio, s);
    unsetenv("IBLCHECK_SHADER_DIR");
    fs::remove_all(shaders);
    EXPECT_NE(edited, key);

    // Another CPU class (llvmpipe generates other code for it).
    setenv("GALLIUM_OVERRIDE_CPU_CAPS", "sse4.1", 1);
    const std::string other_cpu = precompute_store_key(gpu, studio, s);
    unsetenv("GALLIUM_OVERRIDE_CPU_CAPS");
    EXPECT_NE(other_cpu, key);

    // Another build of the tool (a bisect step across a C++ change shares .cache/ with the last one).
    EXPECT_EQ(precompute_store_key(gpu, studio, s, running_binary_hash()), key);
    EXPECT_NE(precompute_store_key(gpu, studio, s, "another build"), key);
    EXPECT_EQ(cost_store_key(gpu, {"pass"}, running_binary_hash()), cost_store_key(gpu, {"pass"}));
    EXPECT_NE(cost_store_key(gpu, {"pass"}, "another build"), cost_store_key(gpu, {"pass"}));
}

// The stores' tool part is the running binary's content: the hash of /proc/self/exe read here on its
// own, and a one-byte change to a file changes a file's hash.
TEST(PrecomputeStore, ToolPartIsTheRunningBinarysContent) {
    std::ifstream exe("/proc/self/exe", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(exe)), std::istreambuf_iterator<char>());
    ASSERT_GT(bytes.size(), 1000u);
    Fnv1a64 h;
    h.update(bytes);
    EXPECT_EQ(running_binary_hash(), h.hex());
    // The precompute and cost stores' code key: in the iblcheck binary, the renderer libraries' hash
    // its build generated (stores.render_code_hash checks that); in a program built without it, like
    // this one, the running binary's content.
    EXPECT_EQ(render_code_hash(), running_binary_hash());
    EXPECT_EQ(metrics_code_hash(), running_binary_hash()); // the metrics store's, the same way

    const fs::path dir = temp_dir("tool_hash");
    std::string copy = bytes.substr(0, 4096);
    std::ofstream(dir / "a", std::ios::binary) << copy;
    copy[2048] ^= 1;
    std::ofstream(dir / "b", std::ios::binary) << copy;
    EXPECT_NE(file_content_hash((dir / "a").string()), file_content_hash((dir / "b").string()));
    EXPECT_EQ(file_content_hash((dir / "missing").string()), "");
    fs::remove_all(dir);
}

namespace {

// The instruction count a render of `spec` reports, with a fresh renderer, no stored precompute,
// and the cost store at `store` ("0": off).
json counted_cost(const TestSpec& spec, const std::string& store) {
    setenv("IBLCHECK_COST_CACHE", store.c_str(), 1);
    const RenderResult r = fresh_render(spec, "0");
    unsetenv("IBLCHECK_COST_CACHE");
    return r.provenance["cost"]["spirv_instructions_per_pixel"];
}

// Every entry of the cost store made to hold `planted` (its last 8 bytes: the count's bits).
void plant(const fs::path& dir, double planted) {
    for (const auto& e : fs::directory_iterator(dir)) {
        std::fstream f(e.path(), std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(std::streamoff(fs::file_size(e.path()) - sizeof planted));
        f.write(reinterpret_cast<const char*>(&planted), sizeof planted);
    }
}

size_t entries(const fs::path& dir) {
    return fs::exists(dir) ? size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator())) : 0u;
}

} // namespace

// A stored instruction count is the one the twin counts (compute, fragment and sampled shading):
// warm equals cold bit for bit. Then every entry is made to hold a planted figure: a render with the
// same inputs reports it (the count is read, not counted again), and a render whose option, scene,
// size, environment or shader include changed does not (it misses, counts, and stores an entry).
TEST(CostStore, AStoredCountIsTheCountedOneAndAChangedInputMisses) {
    const fs::path dir = temp_dir("cost_store");
    TestSpec sampled = furnace_spec({});
    sampled.method = "sampled";
    sampled.options = OptionMap();
    sampled.options.set("cube_size", "32");
    sampled.options.set("samples", "4");
    const std::vector<TestSpec> specs = {furnace_spec({}), furnace_spec({{"shading", "fragment"}}), sampled};
    for (const TestSpec& spec : specs) {
        const json cold = counted_cost(spec, "0");
        ASSERT_TRUE(cold.is_number()) << spec.method << " " << spec.options.canonical();
        EXPECT_EQ(counted_cost(spec, dir.string()), cold); // counts and stores
        EXPECT_EQ(counted_cost(spec, dir.string()), cold); // reads
    }
    ASSERT_EQ(entries(dir), specs.size());

    plant(dir, 12345.0);
    for (const TestSpec& spec : specs) EXPECT_EQ(counted_cost(spec, dir.string()), json(12345.0)) << spec.method;

    TestSpec option = furnace_spec({{"mix_begin_roughness", "0.05"}}), scene = furnace_spec({}), size = furnace_spec({}),
             env = furnace_spec({});
    scene.scene = "sphere";
    size.width = 48;
    size.height = 40;
    env.env = "sky_sun";
    for (const TestSpec* changed : {&option, &scene, &size, &env}) {
        const json c = counted_cost(*changed, dir.string());
        EXPECT_TRUE(c.is_number() && c != json(12345.0)) << changed->scene << " " << changed->options.canonical() << ": " << c;
    }
    EXPECT_EQ(entries(dir), specs.size() + 4);

    // An include of the shading (split_sum.glsl) gained a comment: the same count, under a new key.
    const fs::path shaders = temp_dir("cost_store_shaders");
    fs::copy(vk::shader_dir(), shaders, fs::copy_options::recursive);
    std::ofstream(shaders / "split_sum.glsl", std::ios::app) << "\n// edited\n";
    setenv("IBLCHECK_SHADER_DIR", shaders.c_str(), 1);
    const json edited = counted_cost(specs[0], dir.string());
    unsetenv("IBLCHECK_SHADER_DIR");
    fs::remove_all(shaders);
    EXPECT_TRUE(edited.is_number() && edited != json(12345.0)) << edited;
    EXPECT_EQ(entries(dir), specs.size() + 5);
    fs::remove_all(dir);
}

namespace {

// One furnace test judged linearly and one scored on a display too (its LDR-FLIP map is stored as well).
const char* kMetricsSuite = R"({
  "suite": "mini",
  "defaults": {"env": "constant:1",
               "baseline_tolerances": {"flip.mean": {"max": 0.001}, "ssim.mean": {"min": 0.999}},
               "reference_band": {"flip.mean": {"below": 0.2, "above": 0.1, "abs": 0.0}}},
  "tests": [{"scene": "furnace", "method": "mobile", "variants": [{}]},
            {"scene": "furnace", "method": "mobile", "variants": [{}],
             "display": {"tonemap": "aces_narkowicz", "exposure": 0, "quantize": "srgb8"}}]
})";

// What the store stands in for, per test: the comparisons (metrics, checks, worst block), the
// accuracy and the per-sphere errors (read from the linear FLIP map).
json measured_parts(const RunSummary& run) {
    json out = json::object();
    for (const json& t : run.results["tests"])
        out[t["name"].get<std::string>()] = {t["comparisons"], t["accuracy"], t["per_sphere"], t["verdict"]};
    return out;
}

RunSummary run_with_metrics_store(const FurnaceStore& store, const std::string& metrics_store) {
    setenv("IBLCHECK_METRICS_CACHE", metrics_store.c_str(), 1);
    RunOptions o;
    o.suite = store.suite.string();
    o.goldens = store.goldens;
    o.quiet = true;
    RunSummary r = run_suite(o);
    unsetenv("IBLCHECK_METRICS_CACHE");
    return r;
}

} // namespace

// The metrics of a render against its truth, stored, are the computed ones: a warm run equals a cold
// one and one with the store off, comparisons, accuracy and per-sphere errors alike (the linear map
// and a display test's LDR-FLIP map are stored with the figures). Bit-identical pairs (a render equal
// to its baseline) are not stored. Every entry made to hold a planted figure: the run reports it (read,
// not measured again). Every entry cut in half: measured again, the same. The key changes with either
// image's pixels, size or type, the display space and the build.
TEST(MetricsStore, AStoredComparisonIsTheComputedOneAndAChangedInputMisses) {
    FurnaceStore store("metrics_store", kMetricsSuite);
    const fs::path dir = store.dir / "metrics";
    setenv("IBLCHECK_METRICS_CACHE", dir.c_str(), 1); // bless measures too: not into the checkout's store
    ASSERT_EQ(store.bless_all(), kExitPass);
    unsetenv("IBLCHECK_METRICS_CACHE");
    fs::remove_all(dir);

    const RunSummary off = run_with_metrics_store(store, "0");
    ASSERT_EQ(off.exit_code(), kExitPass) << off.results.dump(1);
    const json expected = measured_parts(off);
    const RunSummary cold = run_with_metrics_store(store, dir.string());
    EXPECT_EQ(measured_parts(cold), expected);
    ASSERT_EQ(entries(dir), 2u); // the two truth comparisons; the baselines are bit-identical
    const RunSummary warm = run_with_metrics_store(store, dir.string());
    EXPECT_EQ(measured_parts(warm), expected);

    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string key = e.path().stem().string();
        setenv("IBLCHECK_METRICS_CACHE", dir.c_str(), 1);
        std::optional<Measured> m = load_measured(key);
        ASSERT_TRUE(m.has_value()) << e.path();
        m->linear.mean = 0.123456;
        save_measured(key, *m);
        unsetenv("IBLCHECK_METRICS_CACHE");
    }
    const RunSummary planted = run_with_metrics_store(store, dir.string());
    for (const json& t : planted.results["tests"]) EXPECT_EQ(t["accuracy"]["flip_mean"], json(0.123456)) << t["name"];

    for (const auto& e : fs::directory_iterator(dir)) fs::resize_file(e.path(), fs::file_size(e.path()) / 2);
    const RunSummary damaged = run_with_metrics_store(store, dir.string());
    EXPECT_EQ(measured_parts(damaged), expected);

    cv::Mat golden(24, 32, CV_32FC3), test;
    cv::randu(golden, 0.0f, 4.0f);
    test = golden * 1.01f;
    const std::string key = metrics_store_key(golden, test, nullptr, "build A");
    EXPECT_EQ(metrics_store_key(golden.clone(), test.clone(), nullptr, "build A"), key);
    cv::Mat pixel = test.clone();
    pixel.at<cv::Vec3f>(23, 31)[2] += 1e-3f;
    cv::Mat other_golden = golden.clone();
    other_golden.at<cv::Vec3f>(0, 0)[0] = 0;
    const DisplaySpace aces, neutral{DisplayTonemap::pbr_neutral};
    EXPECT_NE(metrics_store_key(golden, pixel, nullptr, "build A"), key);
    EXPECT_NE(metrics_store_key(other_golden, test, nullptr, "build A"), key);
    EXPECT_NE(metrics_store_key(golden.reshape(3, 32), test.reshape(3, 32), nullptr, "build A"), key); // 32x24
    EXPECT_NE(metrics_store_key(golden, test, &aces, "build A"), key);
    EXPECT_NE(metrics_store_key(golden, test, &aces, "build A"), metrics_store_key(golden, test, &neutral, "build A"));
    EXPECT_NE(metrics_store_key(golden, test, nullptr, "build B"), key);
}

// A truth read once is kept for the tests after (issue 33), and what the key holds keeps it right: a
// truth rewritten by the golden writer (new pixels, or a new sidecar) is read again, and each reader
// gets its own copy of the pixels.
TEST(GoldenStore, AReferenceRewrittenDuringARunIsReadAgain) {
    const fs::path dir = temp_dir("reference_cache");
    const GoldenStore store(dir);
    TestSpec spec;
    spec.scene = "furnace";
    spec.method = "mobile";
    spec.env = "constant:1";
    const fs::path exr = store.reference_path(spec);
    fs::create_directories(exr.parent_path());
    cv::Mat a(16, 24, CV_32FC3), b;
    cv::randu(a, 0.0f, 2.0f);
    b = a * 0.5f;
    GoldenStore::write_golden(exr, a, {{"source", "a"}});
    std::optional<Golden> first = store.reference(spec);
    ASSERT_TRUE(first.has_value());
    EXPECT_EQ(cv::norm(first->image, a, cv::NORM_INF), 0.0);
    first->image.setTo(0); // the reader's copy
    EXPECT_EQ(cv::norm(store.reference(spec)->image, a, cv::NORM_INF), 0.0);
    GoldenStore::write_golden(exr, b, {{"source", "a"}});
    EXPECT_EQ(cv::norm(store.reference(spec)->image, b, cv::NORM_INF), 0.0);
    GoldenStore::write_golden(exr, b, {{"source", "b"}}); // the same pixels, a new sidecar
    EXPECT_EQ(store.reference(spec)->provenance.value("source", ""), "b");
    fs::remove_all(dir);
}

// A picture the run already drew (a baseline equal to its render, a truth shared by many tests) is
// copied, not drawn again (issue 33): the same bytes as drawing it; other pixels are drawn; a first
// file that is gone is drawn again.
TEST(RunFiles, APictureAlreadyDrawnIsCopiedWithTheSameBytes) {
    const fs::path dir = temp_dir("drawn_png");
    const Artefacts one = Artefacts::for_test(dir, "one"), two = Artefacts::for_test(dir, "two");
    cv::Mat a(20, 30, CV_32FC3), b;
    cv::randu(a, 0.0f, 3.0f);
    b = a.clone();
    b.at<cv::Vec3f>(19, 29)[1] += 0.25f;
    EXPECT_EQ(one.png("test.png", a, false), "images/one/test.png");
    two.png("baseline.png", a, false);
    two.png("other.png", b, false);
    write_png((dir / "fresh_b.png").string(), display_transform(b));
    EXPECT_EQ(read_text(dir / "images/two/baseline.png"), read_text(dir / "images/one/test.png"));
    EXPECT_EQ(read_text(dir / "images/two/other.png"), read_text(dir / "fresh_b.png"));
    EXPECT_NE(read_text(dir / "images/two/other.png"), read_text(dir / "images/one/test.png"));
    const std::string drawn_a = read_text(dir / "images/one/test.png");
    fs::remove_all(dir / "images");
    two.png("again.png", a, false);
    EXPECT_EQ(read_text(dir / "images/two/again.png"), drawn_a);
    fs::remove_all(dir);
}

namespace {
// Seconds since the epoch of "YYYY-MM-DDTHH:MM:SSZ".
std::time_t parse_utc(const std::string& iso) {
    std::tm tm{};
    EXPECT_NE(strptime(iso.c_str(), "%Y-%m-%dT%H:%M:%SZ", &tm), nullptr) << iso;
    return timegm(&tm);
}
} // namespace

// A run's `started` is its start: taken before the first test, not after the last (the nightly of
// 2026-11-26 recorded its end, 48 minutes later, and the commit checked out by then). `started` has a
// resolution of a second, so the run starts just after the clock's second changes and lasts over a
// second (each of its two tests is rendered 12 times at 640x480, timing_repeats: 2.0-2.5 s on a 2-core
// EPYC), so its end is in a later second than its start. A run that still took under a second is
// skipped, said. (It used to render 20 times at 640x480 to last 2.5 s from any start: 23 s of a CTest
// run's test time; 320x240 lasted 2.4 s until the scene moved to a uniform buffer, then 0.6 s.)
TEST(RunFacts, StartedIsTakenBeforeTheTests) {
    FurnaceStore store("run_started", R"({
  "suite": "mini",
  "defaults": {"env": "constant:1", "timing_repeats": 12, "size": "640x480",
               "baseline_tolerances": {"flip.mean": {"max": 0.001}}},
  "tests": [{"scene": "furnace", "method": "mobile", "variants": [{}, {"storage": "rgbm8"}], "reference": false}]
})");
    setenv("IBLCHECK_METRICS_CACHE", "0", 1);
    ASSERT_EQ(store.bless_all(), kExitPass);
    RunOptions o;
    o.suite = store.suite.string();
    o.goldens = store.goldens;
    o.quiet = true;
    // Just after a second begins (a few milliseconds into it).
    const std::time_t now = std::time(nullptr);
    while (std::time(nullptr) == now) std::this_thread::sleep_for(std::chrono::milliseconds(2));
    const std::time_t before = std::time(nullptr);
    const auto t0 = std::chrono::steady_clock::now();
    const RunSummary run = run_suite(o);
    const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    unsetenv("IBLCHECK_METRICS_CACHE");
    ASSERT_EQ(run.exit_code(), kExitPass);
    const std::time_t started = parse_utc(run.results["started"].get<std::string>());
    if (took < 1.0) GTEST_SKIP() << "the run took " << took << " s: its start and end may be within a second";
    EXPECT_EQ(started, before) << "started " << run.results["started"] << ", the run took " << took << " s";
    std::printf("the run took %.2f s from %s\n", took, run.results["started"].get<std::string>().c_str());
}

namespace {
// Options that run the suite file `suite` of measure-only tests quietly: its goldens folder beside
// it, empty (such tests read no golden).
RunOptions measure_only_run(const fs::path& suite) {
    RunOptions o;
    o.suite = suite.string();
    o.goldens = suite.parent_path() / "goldens";
    fs::create_directories(o.goldens / "baseline");
    o.quiet = true;
    return o;
}
} // namespace

// A test's own "timing_repeats" wins over the suite's: the nightly renders its CPU reference once (its
// three 64-spp renders were 68 s of a warm nightly's 158 s, and nobody gates on that time), every
// other test three times. A test's value outside 1..20 is an error naming it.
TEST(RunFacts, ATestsOwnTimingRepeatsWinsOverTheSuites) {
    const fs::path dir = temp_dir("own_repeats");
    write_file(dir / "r.json", R"({
  "suite": "r",
  "defaults": {"env": "constant:1", "timing_repeats": 3, "size": "64x32"},
  "tests": [{"scene": "furnace", "method": "mobile", "baseline": false, "reference": false, "measure_only": true},
            {"scene": "furnace", "method": "mobile", "options": {"storage": "rgbm8"}, "timing_repeats": 1,
             "baseline": false, "reference": false, "measure_only": true}]
})");
    const Suite suite = load_suite((dir / "r.json").string());
    ASSERT_EQ(suite.tests.size(), 2u);
    EXPECT_EQ(suite.tests[0].timing_repeats, 0); // the suite's
    EXPECT_EQ(suite.tests[1].timing_repeats, 1);
    RunOptions o = measure_only_run(dir / "r.json");
    const RunSummary run = run_suite(o);
    ASSERT_EQ(run.exit_code(), kExitPass);
    EXPECT_EQ(run.results["tests"][0]["frame_ms_samples"].size(), 3u);
    EXPECT_FALSE(run.results["tests"][1].contains("frame_ms_samples")) << run.results["tests"][1].dump();
    const Suite nightly = load_suite("nightly");
    for (const TestCase& t : nightly.tests) EXPECT_EQ(t.timing_repeats, t.spec.method == "reference" ? 1 : 0) << t.name;
    write_file(dir / "bad.json", R"({"suite": "bad", "tests": [{"scene": "sphere", "method": "mobile", "timing_repeats": 0}]})");
    std::string err;
    try {
        load_suite((dir / "bad.json").string());
    } catch (const InputError& e) {
        err = e.what();
    }
    EXPECT_NE(err.find("tests[0].timing_repeats: must be an integer in 1..20"), std::string::npos) << err;
    fs::remove_all(dir);
}

namespace {
TestCase timed_case(const std::string& method, const std::string& env, const std::string& variant = "default") {
    TestCase tc;
    tc.spec.method = method;
    tc.spec.scene = "roughness_sweep";
    tc.spec.env = env;
    tc.variant = variant;
    tc.name = method + ".roughness_sweep." + env + "." + variant;
    return tc;
}
TestResult timed_result(double frame_ms, std::vector<double> samples = {}, double ipp = 100) {
    TestResult r;
    RenderFigures f;
    f.width = 64;
    f.height = 32;
    f.texel_count = 1000;
    f.texture_bytes = 8000;
    f.cost = {{"spirv_instructions_per_pixel", ipp}, {"texture_fetches_per_pixel", 4}};
    f.frame_ms = frame_ms;
    f.frame_ms_samples = std::move(samples);
    r.render = f;
    return r;
}
} // namespace

// Tests that differ only in their environment run the same shading work, so with repeated timings
// they form one group named by a pattern over their names; the CPU reference (its cost may follow
// the environment) and a suite without repeats have none (harness/timing_groups.h).
TEST(TimingGroups, TestsThatDifferOnlyInTheirEnvironmentShareOneGroup) {
    EXPECT_EQ(timing_group(timed_case("mobile", "studio"), 3), "mobile.roughness_sweep.*.default");
    EXPECT_EQ(timing_group(timed_case("mobile", "blender:sunrise"), 3), timing_group(timed_case("mobile", "sky_sun"), 3));
    EXPECT_EQ(timing_group(timed_case("sampled", "studio", "samples=64"), 3), "sampled.roughness_sweep.*.samples=64");
    EXPECT_NE(timing_group(timed_case("mobile", "studio", "storage=rgbm8"), 3), timing_group(timed_case("mobile", "studio"), 3));
    EXPECT_EQ(timing_group(timed_case("reference", "studio", "spp=64"), 3), "");
    EXPECT_EQ(timing_group(timed_case("mobile", "studio"), 1), "");
}

// A group of n renders each member ceil(R / n) times: at least R samples in all, as one test alone
// has. In the nightly's 47 four-environment groups, rendering each test 3 times was 59 s of frame time.
TEST(TimingGroups, EachMemberRendersItsShareOfTheRepeats) {
    std::vector<TestCase> tests;
    for (const char* env : {"studio", "sky_sun", "blender:sunrise", "blender:interior"})
        tests.push_back(timed_case("mobile", env));
    for (const char* env : {"studio", "sky_sun"}) tests.push_back(timed_case("sampled", env, "samples=16"));
    tests.push_back(timed_case("mobile", "studio", "storage=rgbm8")); // alone
    tests.push_back(timed_case("reference", "studio", "spp=64"));
    tests.back().timing_repeats = 1; // its own, as the nightly's
    tests.push_back(timed_case("mobile", "sky_sun", "storage=rgbm8"));
    tests.back().timing_repeats = 2; // a member that asks for other repeats is not in the rgbm8 group
    EXPECT_EQ(timing_renders(tests, 3), (std::vector<int>{1, 1, 1, 1, 2, 2, 3, 1, 2}));
    EXPECT_EQ(timing_renders(tests, 1), (std::vector<int>{1, 1, 1, 1, 1, 1, 1, 1, 2}));
}

// After the renders every member reports the group's samples, sorted, and their median; a member
// whose render turned out to be other work (here a different instruction count) keeps its own, and
// one whose render failed is left out.
TEST(TimingGroups, MembersReportTheGroupsSamplesAndMedian) {
    std::vector<TestCase> tests;
    for (const char* env : {"studio", "sky_sun", "blender:sunrise", "blender:interior", "constant:1"})
        tests.push_back(timed_case("mobile", env));
    std::vector<TestResult> results{timed_result(14), timed_result(10), timed_result(12), timed_result(30, {}, 250),
                                    TestResult{}};
    share_timings(tests, 3, results);
    for (size_t i : {0, 1, 2}) {
        ASSERT_TRUE(results[i].render);
        EXPECT_EQ(results[i].render->frame_ms_samples, (std::vector<double>{10, 12, 14})) << i;
        EXPECT_EQ(results[i].render->frame_ms, 12) << i;
        EXPECT_EQ(results[i].render->timing_group, "mobile.roughness_sweep.*.default") << i;
    }
    EXPECT_EQ(results[3].render->frame_ms, 30);
    EXPECT_TRUE(results[3].render->frame_ms_samples.empty());
    EXPECT_EQ(results[3].render->timing_group, "");
    EXPECT_FALSE(results[4].render);

    // Two members of two renders each: four samples, the median between the middle two.
    std::vector<TestCase> two{timed_case("sampled", "studio"), timed_case("sampled", "sky_sun")};
    std::vector<TestResult> r2{timed_result(2, {1, 3}), timed_result(3, {2, 4})};
    share_timings(two, 3, r2);
    EXPECT_EQ(r2[1].render->frame_ms_samples, (std::vector<double>{1, 2, 3, 4}));
    EXPECT_EQ(r2[0].render->frame_ms, 2.5);
    const json j = to_json(r2[0]);
    EXPECT_EQ(j["timing_group"], "sampled.roughness_sweep.*.default");
    EXPECT_EQ(j.get<TestResult>().render->timing_group, "sampled.roughness_sweep.*.default");
}

// A run renders the members of a group their share of the repeats and writes the pooled timings:
// two furnace tests that differ in their constant environment, 3 repeats, so 2 renders each and 4
// samples; a test alone still renders 3 times. Before timing groups each rendered 3 times alone.
TEST(TimingGroups, ARunPoolsTheRendersOfAGroup) {
    const fs::path dir = temp_dir("timing_groups");
    write_file(dir / "g.json", R"({
  "suite": "g",
  "defaults": {"timing_repeats": 3, "size": "64x32"},
  "tests": [{"scene": "furnace", "method": "mobile", "env": ["constant:1", "constant:0.5"],
             "baseline": false, "reference": false, "measure_only": true},
            {"scene": "furnace", "method": "mobile", "env": "constant:1", "options": {"storage": "rgbm8"},
             "baseline": false, "reference": false, "measure_only": true}]
})");
    RunOptions o = measure_only_run(dir / "g.json");
    const RunSummary run = run_suite(o);
    ASSERT_EQ(run.exit_code(), kExitPass);
    const json& t = run.results["tests"];
    ASSERT_EQ(t.size(), 3u);
    for (int i : {0, 1}) {
        EXPECT_EQ(t[i]["timing_group"], "mobile.furnace.*.size=64x32") << t[i].dump();
        EXPECT_EQ(t[i]["frame_ms_samples"].size(), 4u) << t[i].dump();
        EXPECT_EQ(t[i]["frame_ms"], t[0]["frame_ms"]);
    }
    EXPECT_FALSE(t[2].contains("timing_group")) << t[2].dump();
    EXPECT_EQ(t[2]["frame_ms_samples"].size(), 3u) << t[2].dump();
    fs::remove_all(dir);
}

namespace {
// A frame of `rows` x 4 pixels whose every value is `v`.
cv::Mat frame_of(float v, int rows = 3) { return cv::Mat(rows, 4, CV_32FC3, cv::Scalar::all(v)); }
} // namespace

// A sequence's entry is named by every input its frames depend on: any spec field but the frame
// index, the frame count, the shader sources, driver and environment its first frame's render
// recorded, and the renderer code (sequence_store.h). Each changed input names another entry.
TEST(SequenceStore, EveryInputNamesAnotherEntry) {
    TestSpec spec;
    spec.scene = "bumpy_sphere";
    spec.env = "sky_sun";
    spec.options.set("specular_aa", "off");
    const json prov = {{"shader_tree_hash", "s1"}, {"driver", {{"driver", "llvmpipe"}}}, {"env_hash", "e1"}, {"wall_ms", 3}};
    const std::string key = sequence_store_key(spec, 16, prov, "tool1");
    TestSpec frame = spec;
    frame.options.set("frame", "7");
    json timed = prov;
    timed["wall_ms"] = 9; // what the render measured is no input
    EXPECT_EQ(sequence_store_key(frame, 16, timed, "tool1"), key);
    std::set<std::string> keys{key};
    TestSpec other = spec;
    other.options.set("specular_aa", "toksvig");
    keys.insert(sequence_store_key(other, 16, prov, "tool1"));
    other = spec;
    other.env = "studio";
    keys.insert(sequence_store_key(other, 16, prov, "tool1"));
    other = spec;
    other.width = 64;
    keys.insert(sequence_store_key(other, 16, prov, "tool1"));
    other = spec;
    other.shader = "/team/ibl.glsl";
    keys.insert(sequence_store_key(other, 16, prov, "tool1"));
    keys.insert(sequence_store_key(spec, 32, prov, "tool1"));
    keys.insert(sequence_store_key(spec, 16, prov, "tool2"));
    for (const char* k : {"shader_tree_hash", "driver", "env_hash"}) {
        json p = prov;
        p[k] = "changed";
        keys.insert(sequence_store_key(spec, 16, p, "tool1"));
    }
    EXPECT_EQ(keys.size(), 10u) << "a changed input named an entry another input already names";
}

// An entry is read back byte for byte, and only whole and for the first frame it was stored with:
// a first frame that renders differently now, another frame count, a truncated file or the store
// turned off is a miss.
TEST(SequenceStore, ReadsBackOnlyTheWholeEntryOfTheSameFirstFrame) {
    const fs::path dir = temp_dir("sequence_store");
    setenv("IBLCHECK_SEQUENCE_CACHE", dir.c_str(), 1);
    const std::vector<cv::Mat> frames{frame_of(0.25f), frame_of(0.5f), frame_of(1e30f)};
    save_sequence("k", frames);
    const std::optional<std::vector<cv::Mat>> back = load_sequence("k", frame_of(0.25f), 3);
    ASSERT_TRUE(back);
    ASSERT_EQ(back->size(), 3u);
    for (size_t i = 0; i < 3; ++i) EXPECT_TRUE(bit_identical((*back)[i], frames[i])) << i;
    EXPECT_FALSE(load_sequence("k", frame_of(0.2500001f), 3)) << "frame 0 renders differently now";
    EXPECT_FALSE(load_sequence("k", frame_of(0.25f, 2), 3)) << "another size";
    EXPECT_FALSE(load_sequence("k", frame_of(0.25f), 2)) << "another frame count";
    EXPECT_FALSE(load_sequence("other", frame_of(0.25f), 3));
    const fs::path entry = dir / "k.frames";
    ASSERT_TRUE(fs::exists(entry));
    fs::resize_file(entry, fs::file_size(entry) - 1);
    EXPECT_FALSE(load_sequence("k", frame_of(0.25f), 3)) << "truncated";
    save_sequence("k", frames);
    setenv("IBLCHECK_SEQUENCE_CACHE", "0", 1);
    EXPECT_FALSE(load_sequence("k", frame_of(0.25f), 3)) << "the store is off";
    unsetenv("IBLCHECK_SEQUENCE_CACHE");
    fs::remove_all(dir);
}

namespace {
// A suite file of bumpy_sphere temporal tests in `dir` (32x32, 4 frames, the reference at 2x2 rays),
// one per specular_aa value: measure-only, so nothing but the sequences is rendered.
fs::path small_temporal_suite(const fs::path& dir, const std::vector<std::string>& specular_aa) {
    std::string variants;
    for (const std::string& v : specular_aa) variants += (variants.empty() ? "" : ", ") + ("{\"specular_aa\": \"" + v + "\"}");
    write_file(dir / "t.json", R"({"suite": "t", "defaults": {"env": "constant:1", "size": "32x32"},
  "tests": [{"scene": "bumpy_sphere", "method": "mobile", "options": {"ssaa": 1}, "variants": [)" +
                                   variants + R"(],
             "baseline": false, "reference": false, "measure_only": true, "temporal": {"frames": 4, "reference_ssaa": 2}}]})");
    return dir / "t.json";
}
} // namespace

// A temporal test's sequences are kept after the first run and a second run reads them: the same
// temporal figures, bit for bit, with one entry per sequence (the test's, specular_aa=off's and the
// supersampled reference's; the off test's own sequence is the off one). That the second run read
// them shows when their last frames are blacked out: its figures change; a run that does not read
// the store (`run --repeat`'s repeats) renders every frame again and scores as the first.
TEST(SequenceStore, ASecondRunReadsTheSequencesAndScoresThemTheSame) {
    const fs::path dir = temp_dir("sequence_run");
    const fs::path suite = small_temporal_suite(dir, {"off", "toksvig"});
    const fs::path store = dir / "sequences";
    setenv("IBLCHECK_SEQUENCE_CACHE", store.c_str(), 1);
    RunOptions o = measure_only_run(suite);
    const auto temporal_of = [&](bool stored) {
        o.stored_sequences = stored;
        const RunSummary run = run_suite(o);
        EXPECT_EQ(run.exit_code(), kExitPass);
        return run.results["tests"][0]["temporal"].dump() + run.results["tests"][1]["temporal"].dump();
    };
    const std::string first = temporal_of(true);
    std::vector<fs::path> entries;
    if (fs::is_directory(store))
        for (const auto& e : fs::directory_iterator(store))
            if (e.path().extension() == ".frames") entries.push_back(e.path());
    EXPECT_EQ(entries.size(), 3u);
    EXPECT_NE(first.find("flicker"), std::string::npos) << first;
    EXPECT_EQ(temporal_of(true), first);
    for (const fs::path& e : entries) { // the last frame (32 x 32 RGB floats) black, the size kept
        std::string bytes = read_text(e);
        const size_t frame = 32 * 32 * 3 * sizeof(float);
        ASSERT_GT(bytes.size(), frame);
        std::fill(bytes.end() - long(frame), bytes.end(), '\0');
        write_file(e, bytes);
    }
    EXPECT_NE(temporal_of(true), first) << "the second run did not read the stored frames";
    EXPECT_EQ(temporal_of(false), first);
    unsetenv("IBLCHECK_SEQUENCE_CACHE");
    fs::remove_all(dir);
}

// Every specular-AA variant of a scene scores the same `off` sequence against the same reference:
// a worker scores each pair of the sequences it holds once, and the `off` test, whose own sequence
// is the off one, scores it once, not twice. The variants' figures are those of a worker that
// scored everything afresh.
TEST(TemporalScores, AWorkerScoresEachPairOfItsSequencesOnce) {
    const fs::path dir = temp_dir("temporal_scores");
    const Suite suite = load_suite(small_temporal_suite(dir, {"off", "toksvig", "rjump"}).string());
    ASSERT_EQ(suite.tests.size(), 3u);
    const GoldenStore store(dir / "goldens");
    Worker w("");
    std::vector<std::string> shared;
    for (const TestCase& tc : suite.tests) shared.push_back(run_temporal(tc, w, store, {}, "", 0).json.dump());
    // (off, reference), (toksvig, reference), (rjump, reference): three pairs for six scores.
    EXPECT_EQ(w.sequence_scores.size(), 3u);
    for (size_t i = 0; i < suite.tests.size(); ++i) {
        Worker fresh("");
        EXPECT_EQ(run_temporal(suite.tests[i], fresh, store, {}, "", 0).json.dump(), shared[i]) << suite.tests[i].name;
    }
    fs::remove_all(dir);
}

// `--version` reads the commit from iblcheck_commit.txt beside the binary (written at every build),
// so a bisect step whose commit (or a shader edit's dirty state) changed relinks nothing; compiled
// in, it recompiled version.cpp and relinked the tool at every step. Without the file: "unknown".
TEST(BisectStep, VersionReadsTheCommitBesideTheBinary) {
    const fs::path dir = temp_dir("version_file");
    for (const char* f : {"iblcheck", "libiblcheck_oiio.so"}) fs::copy(fs::path(IBLCHECK_BINARY_DIR) / f, dir / f);
    std::string out;
    ASSERT_EQ(run_command((dir / "iblcheck").string() + " --version", out), 0) << out;
    EXPECT_NE(out.find("(commit unknown,"), std::string::npos) << out;
    write_file(dir / "iblcheck_commit.txt", "0123456789ab-dirty\n");
    ASSERT_EQ(run_command((dir / "iblcheck").string() + " --version", out), 0) << out;
    EXPECT_NE(out.find("(commit 0123456789ab-dirty,"), std::string::npos) << out;
    fs::remove_all(dir);
}
} // namespace test_run_speed
