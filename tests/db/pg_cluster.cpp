// The tests' PostgreSQL cluster: tests/db/pg_cluster.sh start/stop, and databases via psql.
#include "tests/db/pg_cluster.hpp"

#include <stdlib.h>
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <fstream>
#include <cstdio>
#include <memory>
#include <stdexcept>

namespace synbench::db::testing {
namespace {

struct Output {
  int status = -1;
  std::string text;
};

Output run(const std::string& command) {
  Output out;
  FILE* p = ::popen(command.c_str(), "r");
  if (!p) return out;
  std::array<char, 4096> buf{};
  while (const std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) out.text.append(buf.data(), n);
  out.status = ::pclose(p);
  return out;
}

std::string quoted(const std::string& s) {
  std::string q = "'";
  for (const char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string& error_text() {
  static std::string e;
  return e;
}

}  // namespace

PgCluster* PgCluster::shared() {
  static std::unique_ptr<PgCluster> cluster = []() -> std::unique_ptr<PgCluster> {
    // Under ctest, one cluster for all the test processes: the fixture test db_pg_cluster_start
    // started it in $SYNBENCH_PG_CLUSTER (db_pg_cluster_stop removes it).
    if (const char* shared_dir = std::getenv("SYNBENCH_PG_CLUSTER")) {
      std::ifstream port_file(std::string(shared_dir) + "/port");
      int port = 0;
      if (!(port_file >> port)) {
        error_text() = std::string("no PostgreSQL test cluster in ") + shared_dir +
                       " (SYNBENCH_PG_CLUSTER): the ctest fixture db_pg_cluster_start did not start it";
        return nullptr;
      }
      auto c = std::unique_ptr<PgCluster>(new PgCluster(shared_dir, port));
      c->owned_ = false;
      return c;
    }
    char tmpl[] = "/tmp/synbench-pg-XXXXXX";
    if (!::mkdtemp(tmpl)) {
      error_text() = "cannot create a temporary directory for the PostgreSQL cluster";
      return nullptr;
    }
    const std::string dir = tmpl;
    const Output o = run(std::string(SYNBENCH_PG_CLUSTER_SCRIPT) + " start " + quoted(dir) + " 2>&1");
    if (o.status != 0) {
      error_text() = "the PostgreSQL test cluster did not start: " + o.text;
      (void)run(std::string(SYNBENCH_PG_CLUSTER_SCRIPT) + " stop " + quoted(dir));
      return nullptr;
    }
    // The port from the file the script writes, not its output: run as `nobody` from a directory
    // nobody may enter (a fresh clone under a private mktemp directory), PostgreSQL's tools print
    // "could not change directory" warnings there, before the port.
    std::ifstream port_file(dir + "/port");
    int port = 0;
    if (!(port_file >> port)) {
      error_text() = "the PostgreSQL test cluster started but wrote no port to " + dir + "/port: " + o.text;
      (void)run(std::string(SYNBENCH_PG_CLUSTER_SCRIPT) + " stop " + quoted(dir));
      return nullptr;
    }
    return std::unique_ptr<PgCluster>(new PgCluster(dir, port));
  }();
  return cluster.get();
}

const std::string& PgCluster::error() { return error_text(); }

PgCluster::~PgCluster() {
  if (owned_) (void)run(std::string(SYNBENCH_PG_CLUSTER_SCRIPT) + " stop " + quoted(dir_));
}

std::string PgCluster::url(const std::string& database) const {
  return "postgresql://synbench@127.0.0.1:" + std::to_string(port_) + "/" + database;
}

std::string PgCluster::socket_target(const std::string& database) const {
  return "host=" + dir_ + " port=" + std::to_string(port_) + " user=synbench dbname=" + database;
}

std::string PgCluster::psql(const std::string& database, const std::string& sql) const {
  const Output o = run("psql -X -q -A -t -v ON_ERROR_STOP=1 " + quoted(socket_target(database)) + " -c " + quoted(sql) + " 2>&1");
  if (o.status != 0) throw std::runtime_error("psql: " + o.text);
  std::string t = o.text;
  while (!t.empty() && t.back() == '\n') t.pop_back();
  return t;
}

std::string PgCluster::create_database() {
  const std::string name = "t" + std::to_string(::getpid()) + "_" + std::to_string(++databases_);
  psql("postgres", "CREATE DATABASE " + name);
  return name;
}

}  // namespace synbench::db::testing
