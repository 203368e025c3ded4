// The database's files pinned by identity and compared with their paths; see file_watch.hpp.
#include "db/file_watch.hpp"

#include <fcntl.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace synbench::db::detail {

FileWatch::FileWatch(FileWatch&& o) noexcept : files_(std::move(o.files_)), lost_(std::move(o.lost_)) {
  o.files_.clear();
}

FileWatch& FileWatch::operator=(FileWatch&& o) noexcept {
  if (this != &o) {
    close_all();
    files_ = std::move(o.files_);
    lost_ = std::move(o.lost_);
    o.files_.clear();
  }
  return *this;
}

FileWatch::~FileWatch() { close_all(); }

void FileWatch::close_all() noexcept {
  for (auto& f : files_)
    if (f.fd >= 0) ::close(f.fd);
  files_.clear();
}

Result<FileWatch> FileWatch::pin(sqlite3* db, const std::filesystem::path& path) {
  FileWatch w;
  const std::pair<std::string, std::string> files[] = {
      {path.string(), ""}, {path.string() + "-wal", " (its write-ahead log)"}, {path.string() + "-shm", " (its shared-memory index)"}};
  for (const auto& [p, role] : files) {
    // O_PATH, not an ordinary descriptor: closing any ordinary descriptor of a file drops every
    // POSIX lock the process holds on it, SQLite's included; an O_PATH one takes no part in
    // locking (Linux), and fstat still reads the open inode's link count.
    const int fd = ::open(p.c_str(), O_PATH | O_CLOEXEC);
    if (fd < 0) {
      // The WAL and its index exist once the connection has read; without them only the
      // database itself is watched.
      if (!role.empty() && errno == ENOENT) continue;
      return make_error(errc::io, p + ": cannot watch the file: " + std::strerror(errno));
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0) {
      const int e = errno;
      ::close(fd);
      return make_error(errc::io, p + ": cannot watch the file: " + std::strerror(e));
    }
    w.files_.push_back({p, role, fd, st.st_dev, st.st_ino});
  }
  // SQLite's own comparison of the inode it opened with the path's: together with ours (made
  // after SQLite's open), the pinned file is the one SQLite writes.
  int moved = 0;
  if (sqlite3_file_control(db, "main", SQLITE_FCNTL_HAS_MOVED, &moved) == SQLITE_OK && moved)
    return make_error(errc::file_lost, path.string() + " was deleted or replaced while it was being opened");
  if (auto s = w.check(); !s) return s.error();
  return w;
}

Status FileWatch::check() {
  if (lost_) return *lost_;
  for (const auto& f : files_) {
    struct stat open_st {}, path_st {};
    const bool have_open = ::fstat(f.fd, &open_st) == 0;
    const std::string links = have_open ? std::to_string(open_st.st_nlink) : std::string("unknown");
    std::string what;
    if (::stat(f.path.c_str(), &path_st) != 0) {
      if (errno != ENOENT)
        what = " can no longer be checked (" + std::string(std::strerror(errno)) + ")";
      else if (have_open && open_st.st_nlink == 0)
        what = " was deleted (link count 0)";
      else
        what = " was moved away or renamed (the open file still has " + links + " links)";
    } else if (path_st.st_dev != f.dev || path_st.st_ino != f.ino) {
      what = " was replaced by another file (inode " + std::to_string(path_st.st_ino) + "; the open one, inode " +
             std::to_string(f.ino) + ", has " + links + " links)";
    } else if (have_open && open_st.st_nlink == 0) {
      what = " was deleted (link count 0)";
    }
    if (!what.empty()) {
      lost_ = make_error(errc::file_lost, f.path + f.role + what + " while open: nothing more is written to it");
      return *lost_;
    }
  }
  return {};
}

}  // namespace synbench::db::detail
