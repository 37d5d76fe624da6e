// Running `subflow` and stopping it with a signal once a line of its stderr was printed
// (tests/cli/interrupt_test.cpp, chunked_reconstruct_test.cpp).
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

namespace subflow::test {

struct KilledRun {
  int exit_code = -1;        // −1: did not exit normally (killed by the signal itself)
  bool signal_sent = false;  // false: the run ended before the trigger line
  std::string err;
};

// Runs `arguments`, reading its stderr line by line; sends `signal_number` once the
// `occurrence`-th line containing `trigger` was printed, then waits for it to end.
inline KilledRun RunAndKill(const std::vector<std::string>& arguments, const std::string& trigger, int occurrence,
                     int signal_number) {
  int pipe_ends[2];
  if (pipe(pipe_ends) != 0) return {};
  const pid_t child = fork();
  if (child == 0) {
    dup2(pipe_ends[1], STDERR_FILENO);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    close(pipe_ends[0]);
    close(pipe_ends[1]);
    std::vector<char*> argv;
    for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(pipe_ends[1]);
  KilledRun run;
  FILE* err = fdopen(pipe_ends[0], "r");
  char line[4096];
  int seen = 0;
  while (std::fgets(line, sizeof line, err)) {
    run.err += line;
    if (!run.signal_sent && std::string(line).find(trigger) != std::string::npos && ++seen == occurrence) {
      kill(child, signal_number);
      run.signal_sent = true;
    }
  }
  std::fclose(err);
  int status = 0;
  waitpid(child, &status, 0);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// Every regular file below `root`, relative.
inline std::set<std::string> FilesBelow(const std::filesystem::path& root) {
  std::set<std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root))
    if (entry.is_regular_file()) files.insert(std::filesystem::relative(entry.path(), root).string());
  return files;
}

}  // namespace subflow::test
