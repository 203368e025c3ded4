// Schema v9: every sweep carries its bench's identity (name, host, device profiles and their
// versions) and an optional unique key a study shard finds its sweep again by.
#include "db/bench_identity.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "db/store.hpp"
#include "synbench/version.hpp"
#include "tests/db/sample_records.hpp"

namespace synbench::db {
namespace {

using testing::TempDir;

SweepMeta meta_named(const std::string& name) {
  SweepMeta m;
  m.name = name;
  m.total_points = 2;
  return m;
}

TEST(BenchIdentity, ASweepWithoutOneGetsTheStoresDefaultingToTheHostName) {
  TempDir dir;
  auto store = Store::open(dir / "id.db");
  ASSERT_TRUE(store) << store.error().message;
  const auto id = store->create_sweep(meta_named("a")).value();
  const auto s = store->get_sweep(id).value();
  char host[256] = {};
  ASSERT_EQ(gethostname(host, sizeof host - 1), 0);
  EXPECT_EQ(s.meta.bench_host, host);
  EXPECT_EQ(s.meta.bench_name, host) << "the bench name defaults to the host name";
  EXPECT_TRUE(s.meta.devices.empty());
  EXPECT_FALSE(s.meta.key);
}

TEST(BenchIdentity, TheStoresBenchIsStampedAndASweepsOwnWins) {
  TempDir dir;
  StoreOptions options;
  options.bench.name = "bench-3";
  options.bench.devices = twin_devices();
  auto store = Store::open(dir / "id.db", options);
  ASSERT_TRUE(store) << store.error().message;
  const auto a = store->get_sweep(store->create_sweep(meta_named("a")).value()).value();
  EXPECT_EQ(a.meta.bench_name, "bench-3");
  ASSERT_EQ(a.meta.devices.size(), 3u);
  EXPECT_EQ(a.meta.devices[0], (DeviceIdentity{"synrm_drive", "synbench twin", std::string(kVersion)}));
  EXPECT_EQ(a.meta.devices[2].device, "vfc_meter");

  SweepMeta own = meta_named("b");
  own.bench_name = "bench-7";
  own.bench_host = "lab-pc-7";
  own.devices = {{"synrm_drive", "ACME drive", "fnv1a64:0123456789abcdef"}};
  const auto b = store->get_sweep(store->create_sweep(own).value()).value();
  EXPECT_EQ(b.meta.bench_name, "bench-7");
  EXPECT_EQ(b.meta.bench_host, "lab-pc-7");
  EXPECT_EQ(b.meta.devices, own.devices);
  // list_sweeps reads the same columns.
  const auto list = store->list_sweeps().value();
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[1].meta.bench_name, "bench-7");
}

TEST(BenchIdentity, AKeyFindsItsSweepAndASecondSweepWithItIsRefused) {
  TempDir dir;
  auto store = Store::open(dir / "key.db");
  ASSERT_TRUE(store) << store.error().message;
  EXPECT_FALSE(store->find_sweep_by_key("study-1/shard-0/3").value());
  SweepMeta m = meta_named("shard");
  m.key = "study-1/shard-0/3";
  const auto id = store->create_sweep(m).value();
  const auto found = store->find_sweep_by_key("study-1/shard-0/3").value();
  ASSERT_TRUE(found);
  EXPECT_EQ(found->id, id);
  EXPECT_EQ(found->meta.key, m.key);
  const auto again = store->create_sweep(m);
  EXPECT_EQ(again.code(), errc::duplicate_key);
  EXPECT_NE(again.error().message.find("study-1/shard-0/3"), std::string::npos) << again.error().message;
  EXPECT_EQ(store->list_sweeps().value().size(), 1u) << "nothing was stored";
  // Sweeps without a key are not unique among themselves.
  ASSERT_TRUE(store->create_sweep(meta_named("x")));
  ASSERT_TRUE(store->create_sweep(meta_named("y")));
  EXPECT_EQ(store->list_sweeps().value().size(), 3u);
}

TEST(BenchIdentity, AProfilesVersionIsItsContentDigestOrItsOwnVersion) {
  const auto a = synbench::Json::parse(R"({"name":"m","signals":{"x":{"address":1}}})");
  const auto reordered = synbench::Json::parse(R"({"signals":{"x":{"address":1}},   "name":"m"})");
  const auto changed = synbench::Json::parse(R"({"name":"m","signals":{"x":{"address":2}}})");
  EXPECT_EQ(profile_version(a), profile_version(reordered));
  EXPECT_NE(profile_version(a), profile_version(changed));
  EXPECT_EQ(profile_version(a).rfind("fnv1a64:", 0), 0u);
  EXPECT_EQ(profile_version(a).size(), 8u + 16u);
  EXPECT_EQ(profile_version(synbench::Json::parse(R"({"name":"m","version":"2.1"})")), "2.1");

  TempDir dir;
  std::ofstream(dir / "p.json") << a.dump(2);
  const auto d = device_identity("vfc_meter", dir / "p.json").value();
  EXPECT_EQ(d, (DeviceIdentity{"vfc_meter", "m", profile_version(a)}));
  EXPECT_EQ(device_identity("vfc_meter", dir / "none.json").code(), errc::io);
}

TEST(BenchIdentity, DevicesJsonRoundTripsAndRefusesOtherShapes) {
  const std::vector<DeviceIdentity> d{{"a", "b", "c"}, {"d", "e", "f"}};
  EXPECT_EQ(parse_devices_json(devices_json(d)).value(), d);
  EXPECT_EQ(parse_devices_json("{}").code(), errc::bad_record);
  EXPECT_EQ(parse_devices_json(R"([{"device":"a"}])").code(), errc::bad_record);
}

}  // namespace
}  // namespace synbench::db
