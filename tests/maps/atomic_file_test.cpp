// Atomic outputs (issue 23, items 3 and 10): a file is replaced whole or not at all; a write
// error (a full disk, a missing folder) is an OutputError naming the file and the reason.
#include "maps/atomic_file.hpp"

#include "tests/test_util.hpp"

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace skylane {
namespace {

using maps::AtomicFile;
using maps::OutputError;
using maps::OutputSet;

/// A folder of its own for one test.
std::string folder(const std::string& name) {
  const std::string dir = test::scratchPath(name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(AtomicFile, CommitReplacesTheFileWholeAndLeavesNoTemporary) {
  const std::string dir = folder("atomic-commit"), path = dir + "/out.json";
  std::ofstream(path) << "old";
  AtomicFile f(path, "--out");
  f.stream() << std::string(200000, 'x');
  // Before the commit the old contents are what a reader sees.
  EXPECT_EQ(test::readFile(path), "old");
  EXPECT_EQ(test::hiddenFiles(dir).size(), 1u);
  f.commit();
  EXPECT_EQ(test::readFile(path), std::string(200000, 'x'));
  EXPECT_TRUE(test::hiddenFiles(dir).empty());
}

TEST(AtomicFile, WithoutACommitTheEarlierFileStaysAndTheTemporaryGoes) {
  const std::string dir = folder("atomic-abort"), path = dir + "/report.json";
  std::ofstream(path) << "earlier run";
  {
    AtomicFile f(path, "--out");
    f.stream() << "half of a new";
  }  // e.g. an exception unwound the command
  EXPECT_EQ(test::readFile(path), "earlier run");
  EXPECT_TRUE(test::hiddenFiles(dir).empty());
}

TEST(AtomicFile, ANewFileGetsTheUsualPermissionsAndAReplacedOneKeepsItsOwn) {
  const std::string dir = folder("atomic-mode");
  const mode_t mask = ::umask(022);
  ::umask(mask);  // read back: the process's mask stays as it was
  maps::writeFileAtomically(dir + "/new.txt", "n", "");
  struct stat info {};
  ASSERT_EQ(::stat((dir + "/new.txt").c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0666u & ~mask);
  std::ofstream(dir + "/kept.txt") << "k";
  ::chmod((dir + "/kept.txt").c_str(), 0600);
  maps::writeFileAtomically(dir + "/kept.txt", "k2", "");
  ASSERT_EQ(::stat((dir + "/kept.txt").c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600u);
}

TEST(AtomicFile, AMissingFolderIsAnErrorNamingTheFileAndTheOption) {
  const std::string msg = test::messageOf<OutputError>([] { AtomicFile f("/nonexistent/m.svg", "--map"); });
  EXPECT_EQ(msg, "/nonexistent/m.svg: cannot write (--map): its folder /nonexistent does not exist");
}

TEST(AtomicFile, AFolderAsTheFileOrAFileAsTheFolderIsAnError) {
  const std::string dir = folder("atomic-folder");
  EXPECT_EQ(test::messageOf<OutputError>([&] { AtomicFile f(dir, "--output"); }),
            dir + ": cannot write (--output): it is a folder, expected a file name");
  std::ofstream(dir + "/plain") << "x";
  EXPECT_EQ(test::messageOf<OutputError>([&] { AtomicFile f(dir + "/plain/out.csv", "--output"); }),
            dir + "/plain/out.csv: cannot write (--output): its folder " + dir + "/plain does not exist");
  EXPECT_NE(test::messageOf<OutputError>([&] { maps::createOutputFolder(dir + "/plain/sub", "--out"); })
                .find(dir + "/plain/sub: cannot write (--out): cannot make the folder: "),
            std::string::npos);
}

TEST(AtomicFile, ADeviceIsWrittenInPlace) {
  // /dev/null cannot be replaced by a rename (and must not be): the output goes straight to it.
  maps::writeFileAtomically("/dev/null", "anything", "--out");
  struct stat info {};
  ASSERT_EQ(::stat("/dev/null", &info), 0);
  EXPECT_TRUE(S_ISCHR(info.st_mode));
  // /dev/full fails every write with ENOSPC: the commit says so.
  EXPECT_EQ(test::messageOf<OutputError>([] { maps::writeFileAtomically("/dev/full", "x", "--out"); }),
            "/dev/full: cannot write (--out): No space left on device");
}

TEST(AtomicFile, AFullDiskIsAnErrorAndTheEarlierFileStays) {
  test::SmallDisk disk("atomic-full");
  if (!disk.mounted()) GTEST_SKIP() << "mounting a tmpfs needs root";
  const std::string path = disk.path() + "/report.json";
  std::ofstream(path) << "earlier run";
  // GIVEN a 64 KiB disk WHEN 200 kB are written THEN the commit fails naming the file and the reason
  EXPECT_EQ(test::messageOf<OutputError>([&] { maps::writeFileAtomically(path, std::string(200000, 'x'), "--out"); }),
            path + ": cannot write (--out): No space left on device");
  // AND the earlier file is as it was, with no temporary left taking the space
  EXPECT_EQ(test::readFile(path), "earlier run");
  EXPECT_TRUE(test::hiddenFiles(disk.path()).empty());
}

TEST(OutputSet, OneFailingFileReplacesNoneOfTheOthers) {
  test::SmallDisk disk("outputset-full");
  if (!disk.mounted()) GTEST_SKIP() << "mounting a tmpfs needs root";
  const std::string a = disk.path() + "/a.txt", b = disk.path() + "/b.txt";
  std::ofstream(a) << "old a";
  std::ofstream(b) << "old b";
  OutputSet set;
  set.add(a, "--out") << "new a";
  set.add(b, "--out") << std::string(200000, 'b');
  const std::string msg = test::messageOf<OutputError>([&] { set.commit(); });
  // (b's bytes fill the disk, so a's last bytes do not fit either: whichever is finished first fails)
  EXPECT_NE(msg.find(".txt: cannot write (--out): No space left on device"), std::string::npos) << msg;
  EXPECT_EQ(test::readFile(a), "old a");
  EXPECT_EQ(test::readFile(b), "old b");
}

TEST(OutputSet, ACommitWritesEveryFileAndDeletesTheStaleOnes) {
  const std::string dir = folder("outputset-commit");
  std::ofstream(dir + "/stale.json") << "from an approval before";
  OutputSet set;
  set.add(dir + "/a.txt", "--out") << "A";
  set.stream(0) << "B";
  set.removeOnCommit(dir + "/stale.json");
  set.removeOnCommit(dir + "/never_written.json");
  set.commit();
  EXPECT_EQ(test::readFile(dir + "/a.txt"), "AB");
  EXPECT_FALSE(std::filesystem::exists(dir + "/stale.json"));
  EXPECT_TRUE(test::hiddenFiles(dir).empty());
}

}  // namespace
}  // namespace skylane
