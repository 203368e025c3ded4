// `synbench report SWEEP_ID`: the one-click report of a stored sweep (docs/report.md) as a
// self-contained HTML file, with the points CSV beside it; the daemon's
// GET /api/sweeps/{id}/report serves the same page.
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "app/report/sweep_report.hpp"
#include "db/store.hpp"
#include "server/cli/args.hpp"
#include "server/cli/commands.hpp"

namespace synbench::cli {

const char* const kReportHelp = R"(usage: synbench report SWEEP_ID [--db FILE] [--out DIR]

Writes the report of a stored sweep (docs/report.md): one self-contained HTML file (no script,
no external resource) with the sweep, its plan, the bench and software metadata, every result
figure as inline SVG (efficiency map and contours, MTPA/ME trajectories, I_m and P_dcM against
angle, position error, deltas, histograms), the MTPA/ME and efficiency tables and the points
left out; and the sweep's points as CSV beside it. Prints the two paths.

  DIR/synbench-report-ID-NAME-YYYY-MM-DD.html
  DIR/synbench-report-ID-NAME-YYYY-MM-DD.csv

options:
  --db FILE|URL  database file (default synbench.db; must exist), or a PostgreSQL lab store
               (postgresql://user@host:port/db; docs/database.md)
  --out DIR    directory to write to (default: the current one; created if missing)
  --help       this text

exit status: 0 written, 1 unknown sweep or a file not written, 2 bad usage or no database
)";

int report_command(const std::vector<std::string>& argv) {
  std::filesystem::path db_path = "synbench.db", out_dir = ".";
  std::int64_t id = 0;
  try {
    Args a(argv, {"--help"}, {"--db", "--out"});
    if (a.has("--help")) {
      std::cout << kReportHelp;
      return 0;
    }
    if (a.positional().size() != 1) throw UsageError("SWEEP_ID", "give one sweep id");
    const std::string& text = a.positional()[0];
    char* end = nullptr;
    const long long v = std::strtoll(text.c_str(), &end, 10);
    if (text.empty() || end != text.c_str() + text.size() || v <= 0)
      throw UsageError("SWEEP_ID", "'" + text + "' is not a sweep id (a positive integer)");
    id = v;
    if (auto d = a.text("--db")) db_path = *d;
    if (auto o = a.text("--out")) out_dir = *o;
    if (!db::is_postgres_target(db_path.string()) && !std::filesystem::is_regular_file(db_path))
      throw UsageError("--db", "no database at '" + db_path.string() + "'");
  } catch (const UsageError& e) {
    std::cerr << "synbench report: " << e.what() << "\n";
    return 2;
  }
  auto store = db::Store::open(db_path);
  if (!store) {
    std::cerr << "synbench report: " << db::shown_target(db_path.string()) << ": " << store.error().message << "\n";
    return 1;
  }
  auto report = report::make_sweep_report(*store, id, report::current_context());
  if (!report) {
    std::cerr << "synbench report: sweep " << id << ": " << report.error().message << "\n";
    return 1;
  }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  for (const auto& [ext, body] : {std::pair<const char*, const std::string*>{".html", &report->html}, {".csv", &report->csv}}) {
    const auto path = out_dir / (report->base_name + ext);
    std::ofstream f(path, std::ios::binary);
    f << *body;
    f.close();
    if (!f) {
      std::cerr << "synbench report: cannot write " << path.string() << "\n";
      return 1;
    }
    std::cout << path.string() << "\n";
  }
  return 0;
}

}  // namespace synbench::cli
