// The tracker database's failures (issue 23, items 8 and 12): a file that is not a tracker
// database, a folder, a database that cannot be opened or written are typed errors naming the
// file (the CLI's exit 2), and a failed open releases the SQLite connection.
#include "planner/tracking/track_store.hpp"

#include "planner/tracking/event_file_sink.hpp"

#include "maps/atomic_file.hpp"
#include "maps/parse_error.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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

/// Runs SQL on a database file outside the store (what damage or another program would do).
void runSql(const std::string& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* err = nullptr;
  EXPECT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err), SQLITE_OK) << (err ? err : "");
  sqlite3_free(err);
  sqlite3_close(db);
}

/// A tracker database with `events` events of 500 bytes and one input position, closed.
std::string filledDatabase(const std::string& name, int events) {
  const std::string path = test::scratchPath(name);
  std::filesystem::remove(path);
  TrackStore store(path);
  store.begin();
  for (int k = 0; k < events; ++k) store.appendEvent("fix", "f", "2020-01-01T00:00:00Z", "{\"pad\":\"" + std::string(500, 'a' + k % 26) + "\"}");
  store.setInputLine("fixes.jsonl", static_cast<std::size_t>(events));
  store.commit();
  return path;
}

TEST(TrackStore, ADamagedPageInTheMiddleIsFoundBeforeTheDatabaseIsUsed) {
  // GIVEN a database of ~40 pages (closed: its WAL is checkpointed into the file)
  const std::string path = filledDatabase("damaged.sqlite", 300);
  ASSERT_EQ(TrackStore(path).events().size(), 300u);
  // WHEN page 20 is overwritten with garbage
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(19 * 4096 + 100);
    f << std::string(3000, '\x5a');
  }
  // THEN opening it is a ParseError naming the file and the damage
  const std::string msg = test::messageOf<maps::ParseError>([&] { TrackStore s(path); });
  EXPECT_EQ(msg.rfind(path + ": field '(tracker database)': got '", 0), 0u) << msg;
  EXPECT_NE(msg.find("expected an undamaged skylane tracker database"), std::string::npos) << msg;
}

TEST(TrackStore, AMissingTableIsRefusedNotRecreated) {
  const std::string path = filledDatabase("dropped.sqlite", 3);
  runSql(path, "DROP TABLE events");
  EXPECT_EQ(test::messageOf<maps::ParseError>([&] { TrackStore s(path); }),
            path + ": field '(tracker database) table events': got 'missing', expected a skylane tracker database, whose "
                   "table events has the columns seq, flight, time, type, json");
  // A file with other tables and none of the tracker's (the service keeps its own tables in the
  // same file) gets the tracker's beside them.
  const std::string shared = test::scratchPath("shared.sqlite");
  std::filesystem::remove(shared);
  runSql(shared, "CREATE TABLE approvals (id TEXT)");
  EXPECT_TRUE(TrackStore(shared).flights().empty());
  // One of the tracker's tables without the others is a damaged tracker database.
  const std::string partial = test::scratchPath("partial.sqlite");
  std::filesystem::remove(partial);
  runSql(partial, "CREATE TABLE inputs (name TEXT PRIMARY KEY, line INTEGER NOT NULL)");
  EXPECT_NE(test::messageOf<maps::ParseError>([&] { TrackStore s(partial); }).find("table flights': got 'missing'"),
            std::string::npos);
}

TEST(TrackStore, ANegativeInputPositionIsRefused) {
  const std::string path = filledDatabase("negative.sqlite", 3);
  runSql(path, "UPDATE inputs SET line = -5");
  EXPECT_EQ(test::messageOf<maps::ParseError>([&] { TrackStore s(path); }),
            path + ": field '(tracker database) inputs[fixes.jsonl].line': got '-5', expected a line number ≥ 0 (the "
                   "database is damaged)");
  // An undamaged database opens as before.
  EXPECT_EQ(TrackStore(filledDatabase("fine.sqlite", 3)).inputLine("fixes.jsonl"), 3u);
}

/// One batch as the session makes it: each event stored, then handed to the file sink; the mark
/// written and the batch committed; the file written only when `written`.
void batch(TrackStore& store, planner::EventFileSink& sink, int first, int count, bool written = true) {
  store.begin();
  for (int k = first; k < first + count; ++k) {
    const std::string line = "{\"event\":\"fix\",\"k\":" + std::to_string(k) + "}";
    store.appendEvent("fix", "f", "", line);
    sink.write(planner::TrackEvent{}, line);
  }
  sink.beforeCommit();
  store.commit();
  if (written) sink.flush();
}

/// The file's lines' k values.
std::vector<int> ks(const std::string& path) {
  std::vector<int> out;
  std::istringstream in(test::readFile(path));
  std::string line;
  while (std::getline(in, line)) out.push_back(nlohmann::json::parse(line).at("k").get<int>());
  return out;
}

std::vector<int> range(int n) {
  std::vector<int> out;
  for (int k = 0; k < n; ++k) out.push_back(k);
  return out;
}

TEST(EventFileSink, AKillBetweenTheCommitAndTheWriteLosesNoEventOnRestart) {
  const std::string db = test::scratchPath("efs_lost.sqlite"), out = test::scratchPath("efs_lost.jsonl");
  std::filesystem::remove(db);
  std::filesystem::remove(out);
  TrackStore store(db);
  {
    planner::EventFileSink sink(out, store);
    batch(store, sink, 0, 5);
    batch(store, sink, 5, 5, false);  // committed, then killed before the file was written
  }
  EXPECT_EQ(ks(out), range(5));
  planner::EventFileSink again(out, store);
  EXPECT_EQ(again.repairedLines(), 5u);
  EXPECT_EQ(ks(out), range(10));  // every committed event once
  batch(store, again, 10, 3);
  EXPECT_EQ(ks(out), range(13));
}

TEST(EventFileSink, ATornLineIsCutAndItsBatchWrittenAgainWhole) {
  const std::string db = test::scratchPath("efs_torn.sqlite"), out = test::scratchPath("efs_torn.jsonl");
  std::filesystem::remove(db);
  std::filesystem::remove(out);
  TrackStore store(db);
  {
    planner::EventFileSink sink(out, store);
    batch(store, sink, 0, 4);
    batch(store, sink, 4, 4);
  }
  // GIVEN a kill in the middle of the last batch's write: the file ends inside a line
  const std::uint64_t whole = std::filesystem::file_size(out);
  std::filesystem::resize_file(out, whole - 30);
  // WHEN the tracker restarts THEN the torn line is gone and the batch is there once
  planner::EventFileSink again(out, store);
  EXPECT_EQ(ks(out), range(8));
  EXPECT_EQ(std::filesystem::file_size(out), whole);
}

TEST(EventFileSink, AnUncommittedBatchNeverReachesTheFile) {
  const std::string db = test::scratchPath("efs_open.sqlite"), out = test::scratchPath("efs_open.jsonl");
  std::filesystem::remove(db);
  std::filesystem::remove(out);
  {
    TrackStore store(db);
    planner::EventFileSink sink(out, store);
    batch(store, sink, 0, 3);
    store.begin();  // a batch in progress when the process is killed: rolled back
    store.appendEvent("fix", "f", "", "{\"event\":\"fix\",\"k\":3}");
    sink.write(planner::TrackEvent{}, "{\"event\":\"fix\",\"k\":3}");
  }
  EXPECT_EQ(ks(out), range(3));
  TrackStore store(db);
  planner::EventFileSink again(out, store);
  EXPECT_EQ(again.repairedLines(), 0u);
  EXPECT_EQ(ks(out), range(3));
  EXPECT_EQ(store.events().size(), 3u);
}

TEST(EventFileSink, AFileLongerThanTheDatabaseRecordedIsRefusedAndANewOneIsStarted) {
  const std::string db = test::scratchPath("efs_other.sqlite"), out = test::scratchPath("efs_other.jsonl");
  std::filesystem::remove(db);
  std::filesystem::remove(out);
  TrackStore store(db);
  {
    planner::EventFileSink sink(out, store);
    batch(store, sink, 0, 3);
    batch(store, sink, 3, 3);
  }
  std::ofstream(out, std::ios::app) << "{\"written by\":\"someone else\"}\n";
  const std::string msg = test::messageOf<maps::ParseError>([&] { planner::EventFileSink s(out, store); });
  EXPECT_NE(msg.find(out + ": field '--out': got '"), std::string::npos) << msg;
  EXPECT_NE(msg.find("another program wrote to it"), std::string::npos) << msg;
  // A removed (rotated) file, shorter than the last batch's start, is a new one: the events go
  // on from there.
  std::filesystem::remove(out);
  planner::EventFileSink fresh(out, store);
  batch(store, fresh, 6, 2);
  EXPECT_EQ(ks(out), (std::vector<int>{6, 7}));
}

}  // namespace
}  // namespace skylane
