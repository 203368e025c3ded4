// Points per second into the store: the same sweep's worth of records into a SQLite file and
// into a PostgreSQL database (the tests' throwaway cluster, tests/db/pg_cluster.sh), one
// insert_point (one transaction, committed durably) at a time as a sweep stores them, reported
// with their ratio. Durability is the same on both: SQLite WAL with synchronous=FULL (fsync per
// commit), PostgreSQL with fsync=on and synchronous_commit=on (the WAL flushed per COMMIT);
// the program prints both settings as it found them. The PostgreSQL server is local (unix
// socket and loopback TCP): a lab store across a network adds its round trip per statement.
//   store_points_bench [--points N] [--rounds R]     (default 1000 points, 3 rounds: best kept)
// Exit 1 when PostgreSQL is not installed (it is a dependency: the README's setup installs it).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

#include "db/store.hpp"
#include "tests/db/pg_cluster.hpp"
#include "tests/db/sample_records.hpp"

using namespace synbench;

namespace {

// Seconds to store `n` points into a new sweep of `store`.
double store_sweep(db::Store& store, int n, int round) {
  db::SweepMeta meta;
  meta.name = "bench round " + std::to_string(round);
  meta.total_points = n;
  const auto id = store.create_sweep(meta);
  if (!id) throw std::runtime_error(id.error().message);
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < n; ++i)
    if (auto s = store.insert_point(*id, i, db::testing::sample_record(i)); !s) throw std::runtime_error(s.error().message);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

int main(int argc, char** argv) {
  int points = 1000, rounds = 3;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--points")) points = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--rounds")) rounds = std::atoi(argv[i + 1]);
  }
  if (points < 1 || rounds < 1) {
    std::cerr << "usage: store_points_bench [--points N>=1] [--rounds R>=1]\n";
    return 2;
  }
  try {
    auto* cluster = db::testing::PgCluster::shared();
    if (!cluster) {
      std::cerr << "store_points_bench: " << db::testing::PgCluster::error() << "\n";
      return 1;
    }
    const std::string database = cluster->create_database();
    db::testing::TempDir dir;
    auto sqlite = db::Store::open(dir / "bench.db");
    auto pg = db::Store::open(cluster->url(database));
    if (!sqlite || !pg) throw std::runtime_error(!sqlite ? sqlite.error().message : pg.error().message);

    double best_sqlite = 1e300, best_pg = 1e300;
    for (int r = 0; r < rounds; ++r) {
      best_sqlite = std::min(best_sqlite, store_sweep(*sqlite, points, r));
      best_pg = std::min(best_pg, store_sweep(*pg, points, r));
    }
    const double sqlite_rate = points / best_sqlite, pg_rate = points / best_pg;
    std::printf("sqlite:     %9.0f points/s  (journal_mode=%s, synchronous=%s [2 = FULL])\n", sqlite_rate,
                sqlite->pragma("journal_mode").value().c_str(), sqlite->pragma("synchronous").value().c_str());
    std::printf("postgresql: %9.0f points/s  (fsync=%s, synchronous_commit=%s, over loopback TCP)\n", pg_rate,
                cluster->psql(database, "SHOW fsync").c_str(), cluster->psql(database, "SHOW synchronous_commit").c_str());
    std::printf("ratio postgresql/sqlite: %.2f  (%d points, best of %d rounds)\n", pg_rate / sqlite_rate, points, rounds);
    // Every point is where it was put: a benchmark that lost points would report nonsense.
    const auto sweeps = pg->list_sweeps().value();
    for (const auto& s : sweeps)
      if (s.points_stored != points) throw std::runtime_error("sweep " + std::to_string(s.id) + " lost points");
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "store_points_bench: " << e.what() << "\n";
    return 1;
  }
}
