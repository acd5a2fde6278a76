#include "service/approval_pool.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

extern char** environ;

namespace skylane::service {

namespace {

constexpr std::string_view kErrorPrefix = "skylane: error: ";
constexpr std::string_view kProgressPrefix = "skylane: approve: ";

/// Starts `argv` with stdout to /dev/null and stderr to a pipe; the pid, and the pipe's read end.
std::pair<pid_t, int> spawnWithStderrPipe(const std::vector<std::string>& args) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) return {-1, -1};
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&fa, fds[1], STDERR_FILENO);
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  close(fds[1]);
  if (rc != 0) {
    close(fds[0]);
    return {-1, -1};
  }
  return {pid, fds[0]};
}

}  // namespace

ApprovalPool::ApprovalPool(std::string program, int workers, std::size_t capacity, Progress progress, Done done)
    : program_(std::move(program)), capacity_(capacity), progress_(std::move(progress)), done_(std::move(done)) {
  for (int i = 0; i < std::max(1, workers); ++i) threads_.emplace_back([this] { work(); });
}

ApprovalPool::~ApprovalPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    for (int pid : children_) kill(pid, SIGKILL);
  }
  wake_.notify_all();
  for (std::thread& t : threads_) t.join();
}

bool ApprovalPool::submit(ApprovalJob job) {
  {
    std::lock_guard lock(mutex_);
    if (queue_.size() >= capacity_) return false;
    queue_.push_back(std::move(job));
  }
  wake_.notify_one();
  return true;
}

std::size_t ApprovalPool::waiting() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

std::size_t ApprovalPool::running() const {
  std::lock_guard lock(mutex_);
  return running_;
}

void ApprovalPool::work() {
  for (;;) {
    ApprovalJob job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      job = std::move(queue_.front());
      queue_.pop_front();
      ++running_;
    }
    const ApprovalOutcome outcome = runChild(job);
    {
      std::lock_guard lock(mutex_);
      --running_;
      if (stopping_) return;  // killed by the shutdown: the job is run again after a restart
    }
    done_(job.id, outcome);
  }
}

ApprovalOutcome ApprovalPool::runChild(const ApprovalJob& job) {
  ApprovalOutcome out;
  const auto [pid, fd] = spawnWithStderrPipe({program_, "approve", job.mission, "--out", job.out_dir, "--progress"});
  if (pid < 0) {
    out.message = "cannot start " + program_ + ": " + std::strerror(errno);
    return out;
  }
  {
    std::lock_guard lock(mutex_);
    children_.push_back(pid);
  }
  std::string pending;
  char buf[4096];
  for (ssize_t n; (n = read(fd, buf, sizeof buf)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    pending.append(buf, static_cast<std::size_t>(n));
    for (std::size_t nl; (nl = pending.find('\n')) != std::string::npos; pending.erase(0, nl + 1)) {
      const std::string line = pending.substr(0, nl);
      if (line.rfind(kErrorPrefix, 0) == 0) out.message = line.substr(kErrorPrefix.size());
      if (line.rfind(kProgressPrefix, 0) == 0) progress_(job.id, line.substr(kProgressPrefix.size()));
    }
  }
  close(fd);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  {
    std::lock_guard lock(mutex_);
    children_.erase(std::remove(children_.begin(), children_.end(), pid), children_.end());
  }
  out.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (!WIFEXITED(status) && out.message.empty()) out.message = "the approval process ended by signal " + std::to_string(WTERMSIG(status));
  return out;
}

}  // namespace skylane::service
