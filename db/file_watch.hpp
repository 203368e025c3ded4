// Whether the files a connection has open are still the ones their paths name. SQLite keeps
// writing into a database file (or its WAL) that was deleted or replaced under it, and every
// commit "succeeds" into an inode nobody can open again: a sweep would report its points while
// they vanish. The store checks before each write transaction, after each commit and before its
// reads, and answers errc::file_lost instead. Internal to db/.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "db/error.hpp"

struct sqlite3;

namespace synbench::db::detail {

class FileWatch {
 public:
  FileWatch() = default;
  // Pins the database file and, where they exist, its -wal and -shm, once `db` has them open;
  // refuses (errc::file_lost) if the file at `path` is not the one SQLite opened.
  static Result<FileWatch> pin(sqlite3* db, const std::filesystem::path& path);
  FileWatch(FileWatch&& o) noexcept;
  FileWatch& operator=(FileWatch&& o) noexcept;
  FileWatch(const FileWatch&) = delete;
  FileWatch& operator=(const FileWatch&) = delete;
  ~FileWatch();

  // ok while every pinned file is still at its path; errc::file_lost naming the file and what
  // happened ("... was deleted (link count 0)", "... was replaced by another file") otherwise.
  // Once lost, always lost: the connection's later writes would not be in the file at the path.
  Status check();

 private:
  struct Pinned {
    std::string path;
    std::string role;  // "" for the database, " (its write-ahead log)", ...
    int fd = -1;
    dev_t dev = 0;
    ino_t ino = 0;
  };
  void close_all() noexcept;
  std::vector<Pinned> files_;
  std::optional<Error> lost_;
};

}  // namespace synbench::db::detail
