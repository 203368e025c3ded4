// `synbench token create`: a new bearer token for the daemon, its digest appended to
// DATA_DIR/tokens.json; the token is printed once, on stdout, and stored nowhere in clear.
#include <iostream>

#include "server/cli/args.hpp"
#include "server/cli/commands.hpp"
#include "server/http/tokens.hpp"

namespace synbench::cli {

const char* const kTokenHelp = R"(usage: synbench token create --role viewer|operator [--data-dir DIR]

Creates a bearer token for `synbench serve` and prints it on stdout, once: the daemon's data
directory keeps only its SHA-256 (DATA_DIR/tokens.json, mode 0600). A running daemon picks the
new token up without a restart. Roles: viewer reads, operator also commands the bench.

  --role R          viewer or operator (required)
  --data-dir DIR    the daemon's data directory (default ./synbench-data)
  --help            this text

exit status: 0 created, 1 the tokens file could not be written, 2 bad input
)";

int token_command(const std::vector<std::string>& argv) {
  http::Role role{};
  std::string data_dir = "synbench-data";
  try {
    Args a(argv, {"--help"}, {"--role", "--data-dir"});
    if (a.has("--help")) {
      std::cout << kTokenHelp;
      return 0;
    }
    if (a.positional().empty()) throw UsageError("create", "missing action (synbench token create --role ROLE)");
    if (a.positional().front() != "create") throw UsageError(a.positional().front(), "unknown action (expected: create)");
    if (a.positional().size() > 1) throw UsageError(a.positional()[1], "unexpected argument");
    const auto r = a.text("--role");
    if (!r) throw UsageError("--role", "required: viewer or operator");
    const auto parsed = http::parse_role(*r);
    if (!parsed) throw UsageError("--role", "'" + *r + "' is not a role (viewer, operator)");
    role = *parsed;
    if (auto d = a.text("--data-dir")) {
      if (d->empty()) throw UsageError("--data-dir", "needs a directory");
      data_dir = *d;
    }
  } catch (const UsageError& e) {
    std::cerr << "synbench token: " << e.what() << "\n";
    return 2;
  }
  http::TokenStore store(std::filesystem::path(data_dir) / "tokens.json");
  std::error_code ec;
  const std::string token = store.create(role, ec);
  if (ec) {
    // A broken file says what is wrong at each JSON pointer; a failed write has only its errno.
    const std::string why = store.load_error();
    std::cerr << "synbench token: cannot update " << store.file().string() << ": " << (why.empty() ? ec.message() : why) << "\n";
    return 1;
  }
  std::cout << token << "\n";
  return 0;
}

}  // namespace synbench::cli
