// Temporary files that a signal must not leave behind. Writers create a
// hidden sibling of the target and rename it into place (image_io.h,
// partial_film.h); while one exists it is registered here, so that the
// signal path (apps/cli/interrupt.cpp) can remove it with unlink(2), which is
// async-signal-safe. A kill -9 cannot be caught: the next write of the same
// target removes the temporary files of processes that no longer run.
#pragma once

#include <filesystem>
#include <string_view>

namespace pathlab {

// Registers `path` for the lifetime of the object. At most 64 are kept at
// once; beyond that a path is simply not registered.
class TempFileRegistration {
 public:
  explicit TempFileRegistration(const std::filesystem::path& path);
  ~TempFileRegistration();
  TempFileRegistration(const TempFileRegistration&) = delete;
  TempFileRegistration& operator=(const TempFileRegistration&) = delete;

 private:
  int slot_ = -1;
};

// Unlinks every registered temporary file. Async-signal-safe: only atomics
// and unlink(2).
void remove_registered_temp_files() noexcept;

// Removes, in `folder`, the files named `prefix` + PID + `rest` where PID is
// the decimal id of a process that no longer exists and `rest` is empty or
// starts with '-' or '.': the temporary files of a writer that was killed
// (kill -9, a crash). Another live process's files, and this process's, are
// left alone. Errors are ignored (a file another process removed first).
void remove_stale_temp_files(const std::filesystem::path& folder, std::string_view prefix);

}  // namespace pathlab
