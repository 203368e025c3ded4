// A pseudo-terminal pair joined by socat, as a null-modem cable between the bench's RTU bus and
// the emulator's RTU server. The test is skipped where socat is not installed.
#pragma once

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>

extern char** environ;

namespace synbench::testing {

class SocatPair {
 public:
  explicit SocatPair(const std::string& tag) {
    dir_ = std::filesystem::temp_directory_path() / ("synbench_" + tag + "_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    a_ = (dir_ / "a").string();
    b_ = (dir_ / "b").string();
    const std::string la = "pty,raw,echo=0,link=" + a_, lb = "pty,raw,echo=0,link=" + b_;
    char* argv[] = {const_cast<char*>("socat"), const_cast<char*>(la.c_str()), const_cast<char*>(lb.c_str()), nullptr};
    if (::posix_spawnp(&pid_, "socat", nullptr, nullptr, argv, environ) != 0) {
      pid_ = -1;
      return;
    }
    for (int i = 0; i < 200 && !(std::filesystem::exists(a_) && std::filesystem::exists(b_)); ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ~SocatPair() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      ::waitpid(pid_, nullptr, 0);
    }
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  bool ok() const { return pid_ > 0 && std::filesystem::exists(a_) && std::filesystem::exists(b_); }
  const std::string& a() const { return a_; }
  const std::string& b() const { return b_; }

 private:
  std::filesystem::path dir_;
  std::string a_, b_;
  pid_t pid_ = -1;
};

}  // namespace synbench::testing
