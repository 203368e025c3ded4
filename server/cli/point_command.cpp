// `synbench point`: one operating point on the in-process twin, on virtual time; or, with
// --bench, through device profiles and Modbus links (hardware, `synbench emulate`).
#include "drivers/json.hpp"

#include <iostream>
#include <memory>

#include "app/bench_backend.hpp"
#include "app/supervised_point.hpp"
#include "bench/current_angle.hpp"
#include "bench/point_procedure.hpp"
#include "bench/safety_supervisor.hpp"
#include "bench/window_plausibility.hpp"
#include "drivers/bench_config.hpp"
#include "drivers/profile/number_format.hpp"
#include "emulator/firmware/estimators/factory.hpp"
#include "emulator/twin_bench.hpp"
#include "emulator/twin_config_schema.hpp"
#include "server/cli/args.hpp"
#include "server/cli/bench_setup.hpp"
#include "server/cli/commands.hpp"

namespace synbench::cli {

const char* const kPointHelp = R"(usage: synbench point --speed-rpm N --load-Nm T --angle-deg A [options]

Runs one operating point on the in-process twin of the bench, on virtual time (as fast as the
CPU allows): starts the drives, brings the bench to the point, waits for steady state, measures
one window on every instrument at once, prints one record, and ends with the ordered stop.
With --bench, the same procedure runs through the device profiles and Modbus links the bench
config names: on real drives, on `synbench emulate`, or on the twin's register map in-process.
The safety supervisor watches every tick (the bench config's "limits"): a limit, a drive fault
or a lost link ends the point with its ordered stop (exit 3), and a point that fails on a
device error is stopped in order too.

required:
  --speed-rpm N      SynRM speed setpoint, 0 < N <= firmware.max_speed_rpm (1500)
  --load-Nm T        PMSM braking torque, 0 <= T <= load limit
  --angle-deg A      current angle in the controller's frame, 0 < A < 90

options:
  --pwm S            capwm (default) or aspwm
  --estimator E      position source: encoder (default), ekf-basic, ekf-rs (with aspwm),
                     hfi, eemf-const, eemf-lut, eemf-rls (docs/estimators.md)
  --udc-V V          DC-bus source voltage; chopper and trips scale with it (default 425)
  --window-s S       measurement window (VFC gate), s (default 1)
  --temp-C T         winding temperature at start (default 50, the bench setpoint)
  --config FILE      twin config JSON (partial: overrides the defaults; see docs/emulator-config.md)
  --seed N           noise seed (default from config)
  --bench FILE       bench config JSON: profile and link of each device (docs/bench-config.md);
                     --config, --seed, --udc-V and --temp-C apply only when its links are the
                     in-process twin (give them to `synbench emulate` otherwise)
  --json             print the record as one JSON object (field names: docs/record.md)
  --budget           also print the point's uncertainty budget (GUM, k = 1: every component,
                     its source, u_i, sensitivity and contributions; docs/uncertainty.md); with
                     --json an object {"record": ..., "budget": ...}
  --help             this text

exit status: 0 measured, 1 failed, 2 bad input, 3 a fault latched during the point
)";

namespace {

drivers::Pwm parse_pwm_flag(const std::optional<std::string>& s) {
  if (!s) return drivers::Pwm::capwm;
  if (auto p = drivers::parse_pwm(*s)) return *p;
  throw UsageError("--pwm", "'" + *s + "' is not a PWM scheme (capwm, aspwm)");
}

drivers::Estimator parse_estimator_flag(const std::optional<std::string>& s) {
  if (!s) return drivers::Estimator::encoder;
  if (auto e = drivers::parse_estimator(*s)) return *e;
  throw UsageError("--estimator", "'" + *s + "' is not an estimator");
}

double required(const Args& a, const std::string& flag) {
  auto v = a.number(flag);
  if (!v) throw UsageError(flag, "is required");
  return *v;
}

}  // namespace

int point_command(const std::vector<std::string>& argv) {
  emulator::TwinConfig config;
  bench::PointRequest req;
  bool json = false, budget = false;
  std::optional<drivers::BenchConfig> bench_config;
  std::optional<drivers::BenchProfiles> profiles;
  bool bench_config_given = false;
  try {
    Args a(argv, {"--json", "--budget", "--help"},
           {"--speed-rpm", "--load-Nm", "--angle-deg", "--pwm", "--estimator", "--udc-V",
            "--window-s", "--temp-C", "--config", "--seed", "--bench"});
    if (a.has("--help")) {
      std::cout << kPointHelp;
      return 0;
    }
    if (!a.positional().empty()) throw UsageError(a.positional().front(), "unexpected argument");
    json = a.has("--json");
    budget = a.has("--budget");
    if (auto file = a.text("--config")) config = emulator::load_twin_config_file(*file);

    req.speed_rpm = required(a, "--speed-rpm");
    req.load_Nm = required(a, "--load-Nm");
    req.angle_deg = required(a, "--angle-deg");
    req.pwm = parse_pwm_flag(a.text("--pwm"));
    req.estimator = parse_estimator_flag(a.text("--estimator"));
    req.window_s = a.number("--window-s").value_or(1.0);

    if (req.speed_rpm <= 0 || req.speed_rpm > config.firmware.max_speed_rpm)
      throw UsageError("--speed-rpm", drivers::format_number(req.speed_rpm) + " is outside (0, " +
                                          drivers::format_number(config.firmware.max_speed_rpm) +
                                          "] rpm (firmware.max_speed_rpm)");
    const double load_max = 1.5 * config.load.pole_pairs * config.load.psi_pm_Wb *
                            config.load.current_limit_A;
    if (req.load_Nm < 0 || req.load_Nm > load_max)
      throw UsageError("--load-Nm", drivers::format_number(req.load_Nm) + " is outside [0, " + drivers::format_number(load_max) +
                                        "] N m (the load drive's current limit)");
    if (!bench::is_motoring_angle(req.angle_deg))
      throw UsageError("--angle-deg", drivers::format_number(req.angle_deg) + " is outside (0, 90) deg");
    if (!(req.window_s >= bench::kMinWindow_s && req.window_s <= 3600))
      throw UsageError("--window-s", drivers::format_number(req.window_s) + " is outside [" +
                                         drivers::format_number(bench::kMinWindow_s) + ", 3600] s");
    if (auto avail = emulator::firmware::make_estimator(req.estimator, config); avail.error)
      throw UsageError("--estimator", "'" + std::string(drivers::name(req.estimator)) +
                                          "' is not available in the twin yet");
    if (auto udc = a.number("--udc-V")) {
      if (*udc < 100 || *udc > 800)
        throw UsageError("--udc-V", drivers::format_number(*udc) + " is outside [100, 800] V");
      config.scale_bus_to(*udc);
    }
    if (auto t = a.number("--temp-C")) {
      if (*t < -40 || *t >= config.firmware.overtemp_trip_C)
        throw UsageError("--temp-C", drivers::format_number(*t) + " is outside [-40, " +
                                         drivers::format_number(config.firmware.overtemp_trip_C) +
                                         ") degC (firmware.overtemp_trip_C)");
      config.thermal.initial_C = *t;
    }
    if (auto seed = a.number("--seed")) {
      if (*seed < 0 || *seed > 2147483647 || *seed != std::floor(*seed))
        throw UsageError("--seed", "must be a whole number in [0, 2147483647]");
      config.sim.seed_int = static_cast<int>(*seed);
    }
    if (auto file = a.text("--bench")) {
      bench_config_given = true;
      auto loaded = load_bench_or_throw(*file, "--bench");
      bench_config = std::move(loaded.config);
      profiles = std::move(loaded.profiles);
      if (!bench_config->on_twin())
        for (const char* flag : {"--config", "--seed", "--udc-V", "--temp-C"})
          if (a.text(flag))
            throw UsageError(flag, "configures the in-process twin, which this bench config does not "
                                   "use; give it to synbench emulate");
    }
  } catch (const UsageError& e) {
    std::cerr << "synbench point: " << e.what() << "\n";
    return 2;
  } catch (const emulator::ConfigError& e) {
    std::cerr << "synbench point: --config: " << e.what() << "\n";
    return 2;
  }

  std::optional<LoadedBench> loaded;
  if (bench_config) loaded = LoadedBench{std::move(*bench_config), std::move(*profiles)};
  auto backend = make_backend(std::move(loaded), config);
  const app::BenchDescription& bench = backend->description();
  bench::PointOptions options;
  options.load_b1_Nms_per_rad = bench.load_b1_Nms_per_rad;
  options.uncertainty = bench.uncertainty;
  options.tick_s = bench.poll_period_s;
  // The same supervisor as the daemon's and a sweep's, on the bench's own limits.
  bench::SafetySupervisor supervisor(backend->devices(), bench.limits, [](const std::string& kind, const std::string& m) {
    if (kind == "fault" || kind == "alarm") std::cerr << "synbench point: " << kind << ": " << m << "\n";
  });
  const auto result = app::run_supervised_point(*backend, supervisor, req, options);
  const auto& proc = result.procedure;
  const double bench_s = backend->clock().now_s();
  if (result.alarm) std::cerr << "synbench point: ALARM: " << result.alarm->detail << "\n";
  if (!proc.has_record()) {
    if (result.trip)
      std::cerr << "synbench point: the safety supervisor tripped (" << drivers::fault_name(result.trip->fault) << ": "
                << result.trip->detail << "); the bench was stopped in order\n";
    else
      std::cerr << "synbench point: " << proc.error() << (result.stopped_after_failure ? "; the bench was stopped in order" : "")
                << "\n";
    std::cerr << backend->link_errors();
    return result.trip ? 3 : 1;
  }
  if (json && budget) {
    synbench::Json out = synbench::Json::object();
    out["record"] = bench::to_json(proc.record());
    out["budget"] = proc.budget() ? bench::to_json(*proc.budget()) : synbench::Json(nullptr);
    std::cout << out.dump() << "\n";
  } else if (json) {
    std::cout << bench::to_json(proc.record()).dump() << "\n";
  } else {
    std::cout << "operating point (" << (bench_config_given ? backend->links() : std::string("twin")) << ", " << bench_s
              << " s of bench time)\n"
              << bench::to_text(proc.record());
    if (budget && proc.budget())
      std::cout << "\nuncertainty budget (GUM, k = 1; docs/uncertainty.md)\n" << bench::to_text(*proc.budget());
  }
  if (proc.record().fault || result.trip) {
    std::cerr << "synbench point: "
              << (result.trip ? "the safety supervisor tripped: " + result.trip->detail : proc.error()) << "\n";
    return 3;
  }
  return 0;
}

}  // namespace synbench::cli
