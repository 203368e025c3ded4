// The db tests' PostgreSQL server: one throwaway cluster (tests/db/pg_cluster.sh in a temporary
// directory), started at first use and removed at exit, or under ctest the one the fixture test
// db_pg_cluster_start started for every test process ($SYNBENCH_PG_CLUSTER); a fresh empty
// database on it per test. When PostgreSQL is not installed, the tests that need it fail with
// the script's message: they never pass silently.
#pragma once

#include <string>

namespace synbench::db::testing {

class PgCluster {
 public:
  // The running cluster, started on the first call; nullptr if it could not start (error()).
  static PgCluster* shared();
  static const std::string& error();

  // A new empty database; its libpq target as a URL over TCP, or with the unix socket directory
  // as key=value pairs.
  std::string create_database();
  std::string url(const std::string& database) const;
  std::string socket_target(const std::string& database) const;
  // Runs SQL in `database` (psql); returns its unaligned output, throws on failure.
  std::string psql(const std::string& database, const std::string& sql) const;

  const std::string& dir() const { return dir_; }
  int port() const { return port_; }

  ~PgCluster();

 private:
  PgCluster(std::string dir, int port) : dir_(std::move(dir)), port_(port) {}
  std::string dir_;
  int port_ = 0;
  int databases_ = 0;
  bool owned_ = true;  // started (and so stopped) by this process
};

}  // namespace synbench::db::testing
