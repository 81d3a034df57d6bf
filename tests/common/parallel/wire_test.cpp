// Wire<T>: every message type's encoding decodes to the message, and its size is what the run
// record counts; bytes that are not one message are refused.
#include <doctest/doctest.h>

#include <cstdint>
#include <vector>

#include "common/parallel/wire.h"
#include "raytrace/integrators/film.h"

namespace pr::par {
namespace {

struct Trivial {
  std::int32_t a;
  float b;
  std::uint64_t c;
};

TEST_CASE("Wire: a trivially copyable message is its bytes, a vector its elements") {
  const Trivial t{-3, 2.5f, 1ull << 40};
  const Bytes tb = encodeMessage(t);
  CHECK(tb.size() == sizeof(Trivial));
  CHECK(wireSize(t) == sizeof(Trivial));
  const Trivial back = decodeMessage<Trivial>(tb);
  CHECK(back.a == -3);
  CHECK(back.b == 2.5f);
  CHECK(back.c == (1ull << 40));

  const std::vector<Trivial> v{{1, 1.0f, 1}, {2, 2.0f, 2}, {3, 3.0f, 3}};
  const Bytes vb = encodeMessage(v);
  CHECK(vb.size() == 3 * sizeof(Trivial));
  CHECK(wireSize(v) == vb.size());
  const auto vback = decodeMessage<std::vector<Trivial>>(vb);
  REQUIRE(vback.size() == 3);
  CHECK(vback[2].a == 3);
  CHECK(decodeMessage<std::vector<Trivial>>(Bytes{}).empty());
}

TEST_CASE("Wire: a film block is its rectangle and its sums, and its size what the record counts") {
  rt::FilmBlock block;
  block.rect = {2, 3, 4, 5};
  block.sums = {1, -2, 3, 1ll << 50, 5, 6, 7, 8, 9, 10, 11, 12};
  const Bytes b = encodeMessage(block);
  CHECK(b.size() == block.bytes());
  CHECK(wireSize(block) == block.bytes());
  const rt::FilmBlock back = decodeMessage<rt::FilmBlock>(b);
  CHECK(back.rect.x0 == 2);
  CHECK(back.rect.y1 == 5);
  CHECK(back.sums == block.sums);
}

TEST_CASE("Wire: bytes short of a message, or left over after one, are refused") {
  const Bytes b = encodeMessage(Trivial{1, 2.0f, 3});
  CHECK_THROWS_AS(decodeMessage<Trivial>(std::span<const std::byte>(b).first(b.size() - 1)), WireError);
  Bytes longer = b;
  longer.push_back(std::byte{0});
  CHECK_THROWS_AS(decodeMessage<Trivial>(longer), WireError);
  // Elements must fill the message.
  CHECK_THROWS_AS(decodeMessage<std::vector<Trivial>>(longer), WireError);
  // A sequence inside a message says its count, and may not claim more than is there.
  Bytes seq;
  WireWriter w(seq);
  const std::vector<std::int32_t> items{4, 5, 6};
  w.sequence(std::span<const std::int32_t>(items));
  CHECK(seq.size() == 8 + 3 * sizeof(std::int32_t));
  WireReader r(seq);
  CHECK(r.sequence<std::int32_t>() == items);
  seq.resize(seq.size() - 4);
  WireReader shortReader(seq);
  CHECK_THROWS_AS(shortReader.sequence<std::int32_t>(), WireError);
}

}  // namespace
}  // namespace pr::par
