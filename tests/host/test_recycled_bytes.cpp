// RecycledBytes (host/links/recycled_bytes.hpp, issue 42): the embedding's bytes for the recording's
// frames are copied into a buffer no reader holds any more, so that a capture after a cut writes
// pages it already has, and never into one a frame still holds.
#include "links/recycled_bytes.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace tissue::host {
namespace {

std::vector<std::uint8_t> bytes_of(std::size_t size, std::uint8_t value) { return std::vector<std::uint8_t>(size, value); }

TEST(RecycledBytes, ABufferNoReaderHoldsIsRefilledOneStillHeldIsNot) {
  RecycledBytes pool;
  const std::vector<std::uint8_t> first = bytes_of(1000, 1), second = bytes_of(1200, 2), third = bytes_of(900, 3);
  auto held = pool.copy(first);
  const std::uint8_t* held_data = held->data();
  // A frame still holds the first copy: the second goes elsewhere and the first is untouched.
  auto next = pool.copy(second);
  EXPECT_NE(next->data(), held_data);
  EXPECT_EQ(*held, first);
  EXPECT_EQ(*next, second);
  // Let go of the first: the next copy refills its buffer (room for twice the first: no allocation).
  held.reset();
  const auto refilled = pool.copy(third);
  EXPECT_EQ(refilled->data(), held_data);
  EXPECT_EQ(*refilled, third);
  EXPECT_EQ(pool.buffer_count(), 2u);
}

TEST(RecycledBytes, AStringLongerThanEveryFreeBufferGetsANewOne) {
  RecycledBytes pool;
  pool.copy(bytes_of(100, 1));  // released at once
  const auto longer = pool.copy(bytes_of(1000, 2));
  EXPECT_EQ(*longer, bytes_of(1000, 2));
  EXPECT_EQ(pool.buffer_count(), 2u);
  // The pool stays bounded when readers keep letting go of longer and longer strings.
  for (std::size_t size = 2000; size < 200000; size *= 2) pool.copy(bytes_of(size, 3));
  EXPECT_LE(pool.buffer_count(), 16u);
}

}  // namespace
}  // namespace tissue::host
