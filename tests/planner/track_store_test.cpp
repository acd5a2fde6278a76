// The tracker database's failures (issue 23, items 8 and 12): a file that is not a tracker
// database, a folder, a database that cannot be opened or written are typed errors naming the
// file (the CLI's exit 2), and a failed open releases the SQLite connection.
#include "planner/tracking/track_store.hpp"

#include "maps/atomic_file.hpp"
#include "maps/parse_error.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace skylane {
namespace {

using planner::TrackStore;

/// The process's open file descriptors.
std::size_t openFiles() {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) ++n;
  return n;
}

TEST(TrackStore, AFileThatIsNotADatabaseIsAParseErrorNamingIt) {
  const std::string path = test::scratchPath("not_a_db.json");
  std::ofstream(path) << "{\"this is\": \"JSON, not SQLite\"}\n" << std::string(2000, ' ') << "\n";
  EXPECT_EQ(test::messageOf<maps::ParseError>([&] { TrackStore s(path); }),
            path + ": field '(tracker database)': got 'file is not a database', expected an undamaged skylane tracker "
                   "database (SQLite 3)");
}

TEST(TrackStore, AFolderIsAParseErrorNamingIt) {
  const std::string dir = test::scratchPath("db_folder");
  std::filesystem::create_directories(dir);
  EXPECT_EQ(test::messageOf<maps::ParseError>([&] { TrackStore s(dir); }),
            dir + ": field '(tracker database)': got 'a folder', expected a tracker database file (SQLite 3)");
}

TEST(TrackStore, ADatabaseThatCannotBeOpenedIsAnOutputErrorNamingIt) {
  const std::string plain = test::scratchPath("plain_file");
  std::ofstream(plain) << "x";
  const std::string path = plain + "/track.sqlite";
  const std::string msg = test::messageOf<maps::OutputError>([&] { TrackStore s(path); });
  EXPECT_EQ(msg.rfind(path + ": cannot write: tracker database: ", 0), 0u) << msg;
  EXPECT_NE(msg.find("unable to open database file"), std::string::npos) << msg;
}

TEST(TrackStore, AFailedOpenReleasesItsConnection) {
  // GIVEN a file that SQLite opens and then refuses (not a database)
  const std::string path = test::scratchPath("not_a_db.bin");
  std::ofstream(path) << std::string(4096, 'z');
  const std::size_t before = openFiles();
  // WHEN the store's constructor throws many times THEN no file stays open (each try used to leak one)
  for (int i = 0; i < 20; ++i) EXPECT_THROW(TrackStore s(path), maps::ParseError);
  EXPECT_EQ(openFiles(), before);
}

TEST(TrackStore, AFullDiskAtACommitIsAnOutputErrorNamingTheDatabase) {
  test::SmallDisk disk("db-full", "128k");
  if (!disk.mounted()) GTEST_SKIP() << "mounting a tmpfs needs root";
  const std::string path = disk.path() + "/track.sqlite";
  TrackStore store(path);
  const std::string line(1000, 'e');
  const std::string msg = test::messageOf<maps::OutputError>([&] {
    for (int batch = 0; batch < 1000; ++batch) {
      store.begin();
      for (int k = 0; k < 20; ++k) store.appendEvent("fix", "f", "2020-01-01T00:00:00Z", line);
      store.commit();
    }
  });
  EXPECT_EQ(msg.rfind(path + ": cannot write: tracker database: ", 0), 0u) << msg;
  EXPECT_NE(msg.find("database or disk is full"), std::string::npos) << msg;
}

}  // namespace
}  // namespace skylane
