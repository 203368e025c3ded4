// The in-process twin as a bench backend, for the tests of app/ (app/ itself never sees the twin;
// server/cli/bench_setup.cpp builds the product's).
#pragma once

#include "app/bench_backend.hpp"
#include "app/bench_description.hpp"
#include "drivers/json.hpp"
#include "emulator/twin_bench.hpp"

namespace synbench::app {

class TwinOnly final : public BenchBackend {
 public:
  explicit TwinOnly(const emulator::TwinConfig& config = {}) : twin_(config) {}
  drivers::BenchDevices devices() override { return twin_.devices(); }
  drivers::Clock& clock() override { return twin_.clock(); }
  synbench::Json describe() const override { return synbench::Json::array(); }
  const BenchDescription& description() const override { return description_; }

 private:
  emulator::TwinBench twin_;
  BenchDescription description_;
};

}  // namespace synbench::app
