// core: output files written whole or not at all.
//
// Set-up: a temporary directory. Checks:
//  - check_output_file / check_output_directory refuse, before any work, an empty path, a
//    directory where a file is expected (and the reverse), a missing directory and a directory
//    where nothing can be created (/proc: access(2) says yes to root there, the probe file
//    does not), and accept ordinary paths;
//  - write_file_atomically writes the bytes exactly and replaces a file whole;
//  - a write that fails part-way (disk full, simulated by a file-size limit RLIMIT_FSIZE: the
//    kernel answers EFBIG as it answers ENOSPC on a full disk) throws Error(kIo) naming the
//    system's reason, leaves the old file as it was and no temporary file;
//  - SIGTERM arriving while a file is being written (a child process writing large files in a
//    loop, the signal sent once its temporary file is seen) ends the process by that signal and
//    leaves no temporary file, and the output is absent or whole;
//  - an HDF5 file built in memory saves to a file HDF5 reads back, and fails the same clean way
//    (libhdf5 1.10 writing to disk directly crashed at exit after such a failure).
#include <gtest/gtest.h>
#include <hdf5.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>
#include <vector>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "draglab/core/files.h"
#include "draglab/core/hdf5_file.h"
#include "draglab/error.h"
#include "support/temp_dir.h"

namespace draglab {
namespace core {
namespace {

namespace fs = std::filesystem;

using TempDir = test::TempDir;

/// Limits the size of files this process may write while it lives (writes past it fail with
/// EFBIG; SIGXFSZ is ignored so that the failure is an error code, as on a full disk).
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &saved_);
    previous_handler_ = signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &saved_);
    signal(SIGXFSZ, previous_handler_);
  }

 private:
  rlimit saved_{};
  void (*previous_handler_)(int) = nullptr;
};

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

ErrorCode code_of(const std::function<void()>& f, std::string* message = nullptr) {
  try {
    f();
  } catch (const Error& e) {
    if (message) *message = e.what();
    return e.code();
  }
  return ErrorCode::kOk;
}

TEST(CoreFiles, OutputPathsAreCheckedBeforeAnyWork) {
  TempDir dir;
  std::string message;
  EXPECT_EQ(code_of([&] { check_output_file("", "--out"); }, &message),
            ErrorCode::kInvalidArgument);
  EXPECT_NE(message.find("--out"), std::string::npos) << message;
  EXPECT_EQ(code_of([&] { check_output_file(dir.file(""), "--out"); }, &message),
            ErrorCode::kInvalidArgument);
  EXPECT_NE(message.find("is a directory"), std::string::npos) << message;
  EXPECT_EQ(code_of([&] { check_output_file(dir.file("missing/x.h5"), "--fields"); }, &message),
            ErrorCode::kInvalidArgument);
  EXPECT_NE(message.find("does not exist"), std::string::npos) << message;
  EXPECT_NE(message.find("--fields"), std::string::npos) << message;
  EXPECT_EQ(code_of([&] { check_output_file("/proc/draglab_test.h5", "--plot"); }, &message),
            ErrorCode::kInvalidArgument);
  EXPECT_NE(message.find("cannot create files"), std::string::npos) << message;
  EXPECT_EQ(code_of([&] { check_output_file("/dev/null", "--out"); }, &message),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { check_output_file(dir.file("ok.csv"), "--out"); }), ErrorCode::kOk);
  std::ofstream(dir.file("existing.csv")) << "x";
  EXPECT_EQ(code_of([&] { check_output_file(dir.file("existing.csv"), "--out"); }), ErrorCode::kOk);
  EXPECT_EQ(code_of([&] { check_output_directory(dir.file("existing.csv"), "--out"); }),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(code_of([&] { check_output_directory(dir.file("new/nested"), "--out"); }),
            ErrorCode::kOk);
  EXPECT_EQ(code_of([&] { check_output_directory("/proc/draglab_test_dir", "--out"); }),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(dir.entries(), 1u);  // the probes left nothing; nothing was created
}

TEST(CoreFiles, AtomicWriteReplacesWholeOrLeavesTheOldFile) {
  TempDir dir;
  const std::string path = dir.file("out.txt");
  write_file_atomically(path, std::string("first"), "--out");
  EXPECT_EQ(read_all(path), "first");
  const std::string big(64 * 1024, 'x');
  write_file_atomically(path, big, "--out");
  EXPECT_EQ(read_all(path), big);
  write_file_atomically(path, std::string("short"), "--out");
  EXPECT_EQ(read_all(path), "short");
  {
    FileSizeLimit limit(8 * 1024);
    std::string message;
    EXPECT_EQ(code_of([&] { write_file_atomically(path, big, "--out"); }, &message),
              ErrorCode::kIo);
    EXPECT_NE(message.find(std::strerror(EFBIG)), std::string::npos) << message;
    EXPECT_NE(message.find("nothing was written"), std::string::npos) << message;
  }
  EXPECT_EQ(read_all(path), "short");  // the old file, whole
  EXPECT_EQ(dir.entries(), 1u);        // no temporary file left
  fs::create_directory(dir.file("a_dir"));
  EXPECT_EQ(code_of([&] { write_file_atomically(dir.file("a_dir"), big, "--out"); }),
            ErrorCode::kInvalidArgument);
  EXPECT_EQ(dir.entries(), 2u);
}

void write_example(Hdf5MemoryFile& file, std::size_t n) {
  std::vector<double> values(n);
  for (std::size_t i = 0; i < n; ++i) values[i] = 0.5 * static_cast<double>(i);
  const hsize_t dims[1] = {n};
  const hid_t space = H5Screate_simple(1, dims, nullptr);
  const hid_t set =
      H5Dcreate2(file.id(), "values", H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(set, 0);
  ASSERT_GE(H5Dwrite(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), 0);
  H5Dclose(set);
  H5Sclose(space);
}

TEST(CoreFiles, TerminatingSignalDuringAWriteLeavesNoTemporaryFile) {
  TempDir dir;
  const std::string path = dir.file("out.bin");
  // Large enough that a write (with its fsync) lasts milliseconds, long enough to be caught.
  const std::size_t size = std::size_t{32} << 20;
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const std::vector<char> bytes(size, 'x');
    try {
      for (;;) write_file_atomically(path, bytes.data(), bytes.size(), "test output");
    } catch (...) {
    }
    ::_exit(3);
  }
  auto temporaries = [&dir] {
    std::vector<std::string> found;
    for (const auto& entry : fs::directory_iterator(dir.path())) {
      const std::string name = entry.path().filename().string();
      if (name.find(".tmp_") != std::string::npos) found.push_back(name);
    }
    return found;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (temporaries().empty() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  const bool seen = !temporaries().empty();
  ::kill(child, SIGTERM);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(seen) << "the child never had a temporary file in 30 s";
  ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_TRUE(temporaries().empty()) << temporaries().front();
  if (fs::exists(path)) {
    EXPECT_EQ(fs::file_size(path), size);
  }
}

TEST(CoreFiles, InMemoryHdf5FileSavesWholeOrNotAtAll) {
  TempDir dir;
  const std::string path = dir.file("values.h5");
  {
    Hdf5MemoryFile file("test file");
    write_example(file, 1000);
    file.save(path);
  }
  const hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const hid_t set = H5Dopen2(f, "values", H5P_DEFAULT);
  std::vector<double> back(1000);
  ASSERT_GE(H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, back.data()), 0);
  EXPECT_EQ(back[999], 499.5);
  H5Dclose(set);
  H5Fclose(f);

  const std::string failed = dir.file("failed.h5");
  {
    Hdf5MemoryFile file("test file");
    write_example(file, 100000);  // 800 kB
    FileSizeLimit limit(64 * 1024);
    EXPECT_EQ(code_of([&] { file.save(failed); }), ErrorCode::kIo);
  }
  EXPECT_FALSE(fs::exists(failed));
  EXPECT_EQ(dir.entries(), 1u);
}

// An input file is checked as what it is before a parser sees it: a directory, an empty file, a
// NUL byte and bytes that are not UTF-8 are named (not reported as a missing key), valid UTF-8
// (2-, 3- and 4-byte sequences) passes, a missing file is kNotFound.
TEST(ReadTextInput, NamesWhatTheFileIs) {
  TempDir dir;
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir.file(name), std::ios::binary) << text;
    return dir.file(name);
  };
  auto message = [](const std::function<void()>& f, ErrorCode expected) {
    try {
      f();
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), expected) << e.what();
      return std::string(e.what());
    }
    ADD_FAILURE() << "no error";
    return std::string();
  };
  const std::string text = "[scene]\nname = \"\xc2\xb5m \xe2\x80\x94 \xf0\x9f\x98\x80\"\n";
  EXPECT_EQ(read_text_input(write("ok.toml", text), "scene file"), text);
  const auto bad = ErrorCode::kInvalidArgument;
  EXPECT_NE(message([&] { read_text_input(dir.path(), "scene file"); }, bad)
                .find("is a directory, not a file"),
            std::string::npos);
  EXPECT_NE(
      message([&] { read_text_input(write("e.toml", " \n\t\n"), "spec"); }, bad).find("spec '"),
      std::string::npos);
  EXPECT_NE(message([&] { read_text_input(write("e2.toml", ""), "spec"); }, bad).find("is empty"),
            std::string::npos);
  EXPECT_NE(message([&] { read_text_input(write("n.toml", std::string("a\0b", 3)), "spec"); }, bad)
                .find("byte 1 is a NUL"),
            std::string::npos);
  EXPECT_NE(message([&] { read_text_input(write("l.toml", "caf\xe9\n"), "spec"); }, bad)
                .find("byte 3 is not UTF-8"),
            std::string::npos);
  EXPECT_NE(message([&] { read_text_input(write("t.toml", "ok\xe2\x80"), "spec"); }, bad)
                .find("byte 2 is not UTF-8"),
            std::string::npos);  // a sequence cut short by the end of the file
  message([&] { read_text_input(dir.file("missing.toml"), "spec"); }, ErrorCode::kNotFound);
}

}  // namespace
}  // namespace core
}  // namespace draglab
