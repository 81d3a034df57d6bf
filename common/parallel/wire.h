// Wire<T>: a message type's encoding - the bytes it takes when it leaves a rank (transport.h),
// and the byte count the run record books for it inside a rank as well, where the message is
// moved, not encoded (shared/DESIGN.md, "Transports"). A figure so does not change with the
// transport. A trivially copyable type travels as its bytes; a type with variable-length parts
// specialises Wire beside its definition. A message's length travels in the transport's
// envelope, so a message that is a vector is its elements alone; a vector inside a message
// writes its count (WireWriter::sequence).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "common/parallel/transport.h"
#include "common/util/allocator.h"

namespace pr::par {

// Bytes that do not decode as the type expected (short, or left over).
class WireError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class WireWriter {
 public:
  explicit WireWriter(Bytes& out) : out_(out) {}
  // Room for n more bytes, so a large encoding grows its buffer once (in 2 MiB pages where
  // the system has them: a message of megabytes is written once, and first touches of 4 KiB
  // pages cost more than the copy; allocator.h).
  // Storage that already has the room (a transport's reused buffer) is left as it is.
  void reserve(std::size_t n) {
    if (out_.capacity() >= out_.size() + n) return;
    out_.reserve(out_.size() + n);
    adviseHugePages(out_.data(), out_.capacity());
  }
  void raw(const void* data, std::size_t n) {
    const auto* p = static_cast<const std::byte*>(data);
    out_.insert(out_.end(), p, p + n);
  }
  template <class T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    raw(&v, sizeof v);
  }
  // Trivially copyable elements, as they are (the rest of a message).
  template <class T>
  void elements(std::span<const T> items) {
    static_assert(std::is_trivially_copyable_v<T>);
    raw(items.data(), items.size_bytes());
  }
  // A count (8 bytes) and the elements: a sequence inside a message.
  template <class T>
  void sequence(std::span<const T> items) {
    value(std::uint64_t(items.size()));
    elements(items);
  }

 private:
  Bytes& out_;
};

class WireReader {
 public:
  explicit WireReader(std::span<const std::byte> in) : in_(in) {}
  void raw(void* data, std::size_t n) {
    if (n > remaining()) throw WireError("a message ends " + std::to_string(n - remaining()) + " bytes short of its encoding");
    if (n == 0) return;  // an empty vector's data() may be null, which memcpy may not be given
    std::memcpy(data, in_.data() + at_, n);
    at_ += n;
  }
  template <class T>
  T value() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    raw(&v, sizeof v);
    return v;
  }
  // The rest of the message as elements of T.
  template <class T>
  std::vector<T> elements() {
    static_assert(std::is_trivially_copyable_v<T>);
    if (remaining() % sizeof(T) != 0) throw WireError("a message's elements do not fill it");
    std::vector<T> out;
    reserveHugePages(out, remaining() / sizeof(T));
    out.resize(remaining() / sizeof(T));
    raw(out.data(), out.size() * sizeof(T));
    return out;
  }
  template <class T>
  std::vector<T> sequence() {
    const auto n = value<std::uint64_t>();
    if (n > remaining() / sizeof(T)) throw WireError("a sequence longer than its message");
    std::vector<T> out;
    reserveHugePages(out, static_cast<std::size_t>(n));
    out.resize(static_cast<std::size_t>(n));
    raw(out.data(), out.size() * sizeof(T));
    return out;
  }
  std::size_t remaining() const { return in_.size() - at_; }

 private:
  std::span<const std::byte> in_;
  std::size_t at_ = 0;
};

// A message type's encoding. Undefined for a type that has none: a type that is not
// trivially copyable gets one by a specialisation beside its definition.
template <class T>
struct Wire;

// The default: a trivially copyable message is its bytes (kBytewise). A specialisation whose
// encoding is not the object's bytes says kBytewise = false.
template <class T>
  requires std::is_trivially_copyable_v<T>
struct Wire<T> {
  static constexpr bool kBytewise = true;
  static std::size_t size(const T&) { return sizeof(T); }
  static void encode(const T& v, WireWriter& w) { w.value(v); }
  static T decode(WireReader& r) { return r.value<T>(); }
};

// Whether T has an encoding, so that a message of it can leave a rank.
template <class T>
concept HasWire = requires { Wire<T>::kBytewise; };

// A message that is a vector: its elements one after another, each as its own Wire encodes it
// (each must then tell its own length: a bytewise element by its size).
template <class T>
  requires HasWire<T>
struct Wire<std::vector<T>> {
  static constexpr bool kBytewise = false;
  static std::size_t size(const std::vector<T>& v) {
    if constexpr (Wire<T>::kBytewise) {
      return v.size() * sizeof(T);
    } else {
      std::size_t n = 0;
      for (const T& item : v) n += Wire<T>::size(item);
      return n;
    }
  }
  static void encode(const std::vector<T>& v, WireWriter& w) {
    if constexpr (Wire<T>::kBytewise)
      w.elements(std::span<const T>(v));
    else
      for (const T& item : v) Wire<T>::encode(item, w);
  }
  static std::vector<T> decode(WireReader& r) {
    if constexpr (Wire<T>::kBytewise) {
      return r.elements<T>();
    } else {
      std::vector<T> out;
      while (r.remaining() > 0) out.push_back(Wire<T>::decode(r));
      return out;
    }
  }
};

template <class T>
std::size_t wireSize(const T& message) {
  return Wire<T>::size(message);
}

template <class T>
Bytes encodeMessage(const T& message) {
  Bytes out;
  WireWriter w(out);
  w.reserve(Wire<T>::size(message));
  Wire<T>::encode(message, w);
  return out;
}

// The message `bytes` encode; throws WireError unless they are exactly one T.
template <class T>
T decodeMessage(std::span<const std::byte> bytes) {
  WireReader r(bytes);
  T message = Wire<T>::decode(r);
  if (r.remaining() != 0) throw WireError(std::to_string(r.remaining()) + " bytes left over after a message");
  return message;
}

}  // namespace pr::par
