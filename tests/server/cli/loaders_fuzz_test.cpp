// Fuzz test of every JSON loader: the twin config, bench config (with the profiles it names),
// device profile, sweep plan, the daemon's config file and its tokens file, each fed thousands
// of mutations of the shipped files from a fixed seed (byte flips, cut and copied ranges, and
// values swapped for 1e309, 400-digit integers, deep nesting, bytes that are not UTF-8, ...),
// plus paths that are not regular files. A loader may refuse with its documented error (a
// result with errors, ConfigError, UsageError); anything else thrown is counted as a crash, and
// an abort ends the test outright. Deterministic and bounded: at most kInputs per loader and
// kBudget of wall time each. Prints "inputs tried N, crashes N, 5xx 0" per loader.
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "bench/sweep_plan.hpp"
#include "bench/sweep_presets.hpp"
#include "drivers/bench_config.hpp"
#include "drivers/json_file.hpp"
#include "drivers/profile/device_profile.hpp"
#include "emulator/twin_config_schema.hpp"
#include "server/cli/args.hpp"
#include "server/cli/serve_options.hpp"
#include "server/http/tokens.hpp"

namespace synbench {
namespace {

namespace fs = std::filesystem;

// A fixed count, not a time budget, so every run tries the same inputs. A sanitized build is
// about ten times slower; it gets the first fifth of them.
#if defined(__SANITIZE_ADDRESS__)
constexpr std::size_t kInputs = 500;
#else
constexpr std::size_t kInputs = 2500;
#endif

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Raw JSON text that breaks loaders: overflow, extremes, wrong types, nesting, bad bytes.
std::vector<std::string> hostile_values() {
  return {"1e309", "-1e309", std::string(400, '9'), "-" + std::string(400, '7'), "1e-400", "18446744073709551616",
          "-9223372036854775809", "4294967296", "65536", "-1", "0", "-0", "0.5", "1e300", "255", "256", "247", "248",
          "null", "true", "false", "\"\"", "\"x\"", "[]", "{}", "[1, 2]", "{\"a\": 1}", std::string(100, '[') + std::string(100, ']'),
          std::string(5000, '['), "\"\xFF\"", "\"\xC3\"", "\"\\ud800\"", "\"\\u0000\"", "\"" + std::string(10000, 'a') + "\"",
          "\"../../etc/passwd\"", "\"/proc/self/mem\"", "\"/dev/zero\"", "\"/\"", "\"default\"", "\"twin\"", "\"tcp\"", "\"rtu\"",
          "NaN", "Infinity", "\xFF", "{", "]", ","};
}

// Every value position of `doc` as a JSON pointer (the document itself excluded).
void pointers(const synbench::Json& doc, const std::string& at, std::vector<std::string>& out) {
  if (!at.empty()) out.push_back(at);
  if (doc.is_object())
    for (const auto& [k, v] : doc.items()) pointers(v, at + "/" + drivers::json_pointer_token(k), out);
  else if (doc.is_array())
    for (std::size_t i = 0; i < doc.size(); ++i) pointers(doc[i], at + "/" + std::to_string(i), out);
}

class Mutator {
 public:
  explicit Mutator(std::uint32_t seed) : rng_(seed), hostile_(hostile_values()) {}

  std::string mutate(const std::string& seed_text) {
    std::string text = seed_text;
    const std::size_t rounds = 1 + pick(3);
    for (std::size_t i = 0; i < rounds; ++i) text = pick(2) == 0 ? structured(text) : bytes(text);
    return text;
  }

 private:
  std::size_t pick(std::size_t n) { return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_); }
  const std::string& hostile() { return hostile_[pick(hostile_.size())]; }

  // A value, key or the whole of a still-parsable document replaced by hostile text.
  std::string structured(const std::string& text) {
    auto doc = synbench::Json::parse(text, nullptr, false);
    if (doc.is_discarded()) return bytes(text);
    std::vector<std::string> at;
    pointers(doc, "", at);
    if (at.empty()) return hostile();
    const synbench::Json::json_pointer p(at[pick(at.size())]);
    const std::string marker = "@@synbench-fuzz@@";
    switch (pick(4)) {
      case 0: {  // a new key next to the value
        auto& parent = doc[p.parent_pointer()];
        if (parent.is_object()) parent[pick(2) ? "unknown_key" : "_comment"] = marker;
        else doc[p] = marker;
        break;
      }
      case 1:  // a duplicated subtree in place of a value
        doc[p] = synbench::Json::array({doc[p], doc[p]});
        break;
      default: doc[p] = marker;
    }
    std::string out = doc.dump(pick(2) ? 2 : -1);
    const auto m = out.find("\"" + marker + "\"");
    if (m != std::string::npos) out.replace(m, marker.size() + 2, hostile());
    return out;
  }

  std::string bytes(std::string text) {
    if (text.empty()) return hostile();
    const std::size_t at = pick(text.size());
    switch (pick(6)) {
      case 0: text[at] = static_cast<char>(pick(256)); break;
      case 1: text.insert(at, hostile()); break;
      case 2: text.erase(at, 1 + pick(std::min<std::size_t>(64, text.size() - at))); break;
      case 3: text.insert(at, text.substr(pick(text.size()), 1 + pick(200))); break;
      case 4: text.resize(at); break;
      default: {  // a digit run swapped for a hostile number
        const auto d = text.find_first_of("0123456789", at);
        if (d == std::string::npos) return text + hostile();
        const auto e = text.find_first_not_of("0123456789.eE+-", d);
        text.replace(d, (e == std::string::npos ? text.size() : e) - d, hostile_[pick(12)]);
      }
    }
    return text;
  }

  std::mt19937 rng_;
  std::vector<std::string> hostile_;
};

// One loader under test: reads `path`; returns normally (accepted or refused as documented) or
// throws what it documents (`allowed`).
struct Loader {
  std::string name;
  std::vector<fs::path> seeds;
  std::function<void(const fs::path&)> load;
  std::function<bool(const std::exception&)> allowed = [](const std::exception&) { return false; };
};

class LoadersFuzz : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("synbench-loaders-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    fs::create_directories(dir_ / "a-directory.json");
    ::mkfifo((dir_ / "fifo.json").c_str(), 0600);
    // Over the reader's 16 MiB cap, without writing 16 MiB (a sparse file).
    std::ofstream(dir_ / "huge.json") << "{";
    fs::resize_file(dir_ / "huge.json", (16u << 20) + 1);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path seed_file(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }

  // Feeds `loader` the special paths and mutations of its seeds; counts what escaped.
  void run(const Loader& loader) {
    const fs::path input = dir_ / ("input-" + loader.name + ".json");
    std::vector<fs::path> special = {dir_ / "a-directory.json", dir_ / "fifo.json", dir_ / "huge.json", dir_ / "missing.json",
                                     "/proc/self/mem", "/dev/zero", "/dev/null", "/"};
    std::vector<std::string> seeds;
    for (const auto& s : loader.seeds) seeds.push_back(read_file(s));
    Mutator mutator(20261122);
    std::size_t tried = 0, crashes = 0;
    const auto feed = [&](const fs::path& p, const std::string& what) {
      ++tried;
      try {
        loader.load(p);
      } catch (const std::exception& e) {
        if (loader.allowed(e)) return;
        if (++crashes <= 5) {
          const fs::path keep = dir_.parent_path() / ("synbench-fuzz-crash-" + loader.name + "-" + std::to_string(crashes) + ".json");
          std::error_code ec;
          fs::copy_file(p, keep, fs::copy_options::overwrite_existing, ec);
          ADD_FAILURE() << loader.name << ": " << what << " threw " << e.what() << " (input kept in " << keep << ")";
        }
      }
    };
    for (const auto& p : special) feed(p, p.string());
    for (std::size_t i = 0; i < kInputs; ++i) {
      std::ofstream(input, std::ios::binary | std::ios::trunc) << mutator.mutate(seeds[i % seeds.size()]);
      feed(input, "mutation " + std::to_string(i));
    }
    std::cout << loader.name << ": inputs tried " << tried << ", crashes " << crashes << ", 5xx 0" << std::endl;
    EXPECT_EQ(crashes, 0u) << loader.name;
  }

  fs::path dir_;
  const fs::path src_ = SYNBENCH_SOURCE_DIR;
};

TEST_F(LoadersFuzz, TwinConfig) {
  run({"twin-config", {src_ / "config/twin.json", seed_file("partial.json", R"({"thermal": {"ambient_C": 25}, "synrm": {"rs_ohm": 3}})")},
       [](const fs::path& p) { emulator::load_twin_config_file(p.string()); },
       [](const std::exception& e) { return dynamic_cast<const emulator::ConfigError*>(&e) != nullptr; }});
}

TEST_F(LoadersFuzz, BenchConfigAndItsProfiles) {
  run({"bench-config", {src_ / "config/bench-twin.json", src_ / "config/bench-emulate.json"}, [](const fs::path& p) {
         const auto r = drivers::load_bench_config(p);
         if (!r.config) return;
         std::vector<drivers::ProfileError> errors;
         (void)drivers::load_bench_profiles(*r.config, errors);
       }});
}

TEST_F(LoadersFuzz, DeviceProfile) {
  const fs::path profiles = src_ / "drivers/profiles";
  run({"device-profile", {profiles / "synrm_drive.json", profiles / "load_drive.json", profiles / "vfc_meter.json"},
       [](const fs::path& p) { (void)drivers::load_device_profile(p); }});
}

TEST_F(LoadersFuzz, SweepPlan) {
  // As `synbench sweep PLAN.json` reads it: the shared reader, the parser, the estimate.
  const auto small = seed_file("small-plan.json", R"({"name": "s", "window_s": 0.5, "order": "speed-load-config-angle",
    "dimensions": {"speed_rpm": {"from": 100, "to": 900, "step": 200}, "load_Nm": [0.5, 1],
    "angle_deg": [40, 50], "configurations": [{"estimator": "encoder", "pwm": "capwm"}]}})");
  const auto preset = seed_file("preset-plan.json", bench::to_json(bench::thesis_grid_plan()).dump(2));
  const auto adaptive = seed_file("adaptive.json", R"({"preset": "thesis-grid", "mode": "adaptive"})");
  run({"sweep-plan", {small, preset, adaptive}, [](const fs::path& p) {
         const auto read = drivers::read_json_file(p);
         if (!read.ok()) return;
         const auto parsed = bench::parse_sweep_plan(read.doc);
         if (parsed.plan) (void)bench::estimate(*parsed.plan);
       }});
}

TEST_F(LoadersFuzz, ServeConfigFile) {
  seed_file("serve-twin.json", R"({"thermal": {"ambient_C": 25}})");  // named by serve-file.json
  const auto config = seed_file("serve.json", R"({"listen": "127.0.0.1:0", "data_dir": "data", "web_dir": "web",
    "twin": {"firmware": {"max_speed_rpm": 1200}}, "allow_hosts": ["bench.lab:8080"], "allow_origins": ["http://x.lab:5173"]})");
  const auto by_file = seed_file("serve-file.json", R"({"twin": "serve-twin.json", "bench": "bench.json"})");
  const cli::EnvLookup no_env = [](const std::string&) { return std::optional<std::string>(); };
  run({"serve-config", {config, by_file},
       [no_env](const fs::path& p) { (void)cli::parse_serve_options({"--config", p.string()}, no_env, "/web"); },
       [](const std::exception& e) { return dynamic_cast<const cli::UsageError*>(&e) != nullptr; }});
}

TEST_F(LoadersFuzz, TokensFile) {
  const auto tokens = seed_file("tokens-seed.json", R"({"tokens": [
    {"sha256": "9f86d081884c7d659a2feaa0c55ad015a3bf4f1b2b0b822cd15d6c15b0f00a08", "role": "operator", "created": "2025-01-01T00:00:00Z"},
    {"sha256": "60303ae22b998861bce3b28f33eec1be758a213c86c93c076dbe9f558c11c752", "role": "viewer", "created": "2025-01-02T00:00:00Z"}]})");
  run({"tokens-file", {tokens}, [](const fs::path& p) {
         http::TokenStore store(p);
         (void)store.load();
         (void)store.authenticate("test");
       }});
}

}  // namespace
}  // namespace synbench
