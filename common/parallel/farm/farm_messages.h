// The farm's messages (farm.h), shared by the master and the server: one tag each way, the
// first byte saying what the message is, then its fields (wire.h).
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "common/parallel/process_group.h"
#include "common/parallel/wire.h"

namespace pr::par::farm {

// Each farm run of a command (FarmOptions::run) has tags of its own, so that a message of one
// run (a server's hello for the next run sent while the master still waits for another
// server's goodbye, a lost server's late result) never reaches another run's protocol.
// run >= 0 (a count); tags 1100 .. 3099, below ServerGroupTransport's offset.
inline int toMasterTag(int run) { return ProcessGroup::kFirstUserTag + 100 + 2 * (run % 1000); }
inline int toServerTag(int run) { return toMasterTag(run) + 1; }

// Server to master.
enum class ServerSays : std::uint8_t { Hello = 1, Ready = 2, Result = 3, Failed = 4, Alive = 5, Bye = 6 };
// Master to server.
enum class MasterSays : std::uint8_t { Welcome = 1, Mismatch = 2, Job = 3, Wait = 4, Stop = 5, StopFailed = 6 };

// Messages are their bytes (wire.h): no padding, so no byte of them is left unset.
struct Hello {
  std::uint64_t contentHash = 0;
  std::int32_t pes = 1;
  std::int32_t unused = 0;
};
struct Ready {
  double prepareSeconds = 0.0;
  std::uint64_t prepareMessages = 0, prepareBytes = 0;  // between servers (shared pre-passes)
};
// A result's header; the result's bytes follow.
struct ResultHeader {
  double busySeconds = 0.0;  // on this job
  double idleSeconds = 0.0;  // waiting for jobs since ready, so far
  std::int32_t job = 0;
  std::int32_t unused = 0;
};
struct Failed {
  std::int32_t status = 1;  // the text follows
};
struct Bye {
  double cpuSeconds = 0.0;  // the server process's CPU time (user and system) since its hello
};

template <class Kind, class T>
Bytes message(Kind kind, const T& fields, std::span<const std::byte> tail = {}) {
  Bytes out;
  WireWriter w(out);
  w.reserve(1 + sizeof(T) + tail.size());
  w.value(kind);
  w.value(fields);
  w.elements(tail);
  return out;
}

template <class Kind>
Bytes message(Kind kind) {
  Bytes out(1);
  out[0] = std::byte(kind);
  return out;
}

inline std::string textOf(WireReader& r) {
  const auto chars = r.elements<char>();
  return std::string(chars.begin(), chars.end());
}

}  // namespace pr::par::farm
