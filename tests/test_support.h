// Shared helpers for tests: where the shared glTF models are, how to skip when they are
// absent, and how to run the parrender executable and capture its exit status and output.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <initializer_list>
#include <string>

namespace pr::test {

// ../shared/scenes, or $PARRENDER_SCENES when set.
inline std::filesystem::path sharedScenes() {
  if (const char* env = std::getenv("PARRENDER_SCENES"); env && *env) return env;
  return PARRENDER_SHARED_SCENES_DEFAULT;
}

// True when the shared models are present; otherwise prints the line CTest reads as "skipped".
inline bool haveSharedScenes() {
  if (std::filesystem::is_directory(sharedScenes())) return true;
  std::printf("SKIPPED: shared glTF models not found at %s (set PARRENDER_SCENES to their folder)\n",
              sharedScenes().string().c_str());
  return false;
}

inline std::filesystem::path sourceDir() { return PARRENDER_SOURCE_DIR; }
inline std::filesystem::path binaryDir() { return PARRENDER_BINARY_DIR; }

// A fresh scratch directory for one test, under the build tree.
inline std::filesystem::path scratchDir(const std::string& name) {
  auto dir = binaryDir() / "test_scratch" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Concatenates with append: GCC 12 warns (-Wrestrict, falsely) on chains of literal + std::string.
inline std::string join(std::initializer_list<std::string> parts) {
  std::string out;
  for (const std::string& p : parts) out.append(p);
  return out;
}
// A path in double quotes, for a runParrender command line.
inline std::string quoted(const std::filesystem::path& p) { return join({"\"", p.string(), "\""}); }
// The bundled Cornell box (scenes/cornell.gltf), quoted for a command line.
inline std::string cornell() { return quoted(sourceDir() / "scenes" / "cornell.gltf"); }

struct CommandResult {
  int exitStatus = -1;
  std::string output;  // stdout and stderr together
};

// Runs a shell command line, capturing stdout+stderr and the exit status.
inline CommandResult runCommand(const std::string& commandLine) {
  CommandResult result;
  const std::string command = commandLine + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return result;
  char buffer[4096];
  size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) result.output.append(buffer, n);
  int status = pclose(pipe);
  result.exitStatus = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// Runs `parrender ARGS` through the shell, capturing stdout+stderr and the exit status.
inline CommandResult runParrender(const std::string& args) {
  return runCommand(std::string("\"") + PARRENDER_EXE + "\" " + args);
}

}  // namespace pr::test
