#include "support/toml_mutator.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace tissue::fuzz {

namespace {

// A node and where it sits: in a table under a key, or in an array at an index.
struct Place {
  toml::table* table = nullptr;
  std::string key;
  toml::array* array = nullptr;
  std::size_t index = 0;
  toml::node* node = nullptr;
};

void collect(toml::table& table, std::vector<Place>& places, std::vector<std::string>& keys);

void collect(toml::array& array, std::vector<Place>& places, std::vector<std::string>& keys) {
  for (std::size_t i = 0; i < array.size(); ++i) {
    places.push_back(Place{nullptr, {}, &array, i, array.get(i)});
    if (auto* t = array.get(i)->as_table()) collect(*t, places, keys);
    if (auto* a = array.get(i)->as_array()) collect(*a, places, keys);
  }
}

void collect(toml::table& table, std::vector<Place>& places, std::vector<std::string>& keys) {
  for (auto&& [key, node] : table) {
    places.push_back(Place{&table, std::string(key.str()), nullptr, 0, &node});
    keys.emplace_back(key.str());
    if (auto* t = node.as_table()) collect(*t, places, keys);
    if (auto* a = node.as_array()) collect(*a, places, keys);
  }
}

// Replaces the node at `place` by `value`.
template <class Value>
void put(const Place& place, Value&& value) {
  if (place.table != nullptr) {
    place.table->insert_or_assign(place.key, std::forward<Value>(value));
  } else {
    place.array->replace(place.array->cbegin() + static_cast<std::ptrdiff_t>(place.index), std::forward<Value>(value));
  }
}

// A value at the edges of what a reader must refuse or take, of any type.
void boundary_value(const Place& place, std::mt19937& rng) {
  constexpr double INF = std::numeric_limits<double>::infinity();
  static const double doubles[] = {0.0, -0.0, -1.0, 1.0, 1e-300, 1e300, -1e300, 5e-324, INF, -INF,
                                   std::numeric_limits<double>::quiet_NaN(), 0.5, 1e-9, 2.0, 1e6};
  static const std::int64_t integers[] = {0, -1, 1, 2, 255, 65535, 65536, 2147483647, 2147483648LL,
                                          -2147483648LL, std::numeric_limits<std::int64_t>::max(),
                                          std::numeric_limits<std::int64_t>::min()};
  switch (rng() % 5) {
    case 0: put(place, doubles[rng() % std::size(doubles)]); break;
    case 1: put(place, integers[rng() % std::size(integers)]); break;
    case 2: put(place, std::string(rng() % 3 == 0 ? std::size_t{4096} : rng() % 4, 'x')); break;
    case 3: put(place, (rng() & 1U) != 0); break;
    default: put(place, toml::array{}); break;
  }
}

void scale_number(const Place& place, std::mt19937& rng) {
  if (auto* f = place.node->as_floating_point()) {
    const double factors[] = {-1.0, 0.0, 10.0, 0.1, 1e6, 1e-6, 1.0 + 1e-12};
    put(place, f->get() * factors[rng() % std::size(factors)]);
  } else if (auto* i = place.node->as_integer()) {
    const std::uint64_t deltas[] = {~std::uint64_t{0}, 1, ~std::uint64_t{1}, 1000};  // -1, 1, -2, 1000, wrapping
    put(place, static_cast<std::int64_t>(static_cast<std::uint64_t>(i->get()) + deltas[rng() % std::size(deltas)]));
  } else {
    boundary_value(place, rng);
  }
}

// A string's bytes mutated by libFuzzer (up to 64 longer).
void mutate_string(const Place& place, std::mt19937& rng) {
  auto* s = place.node->as_string();
  if (s == nullptr) return boundary_value(place, rng);
  std::string text = s->get();
  const std::size_t size = text.size();
  text.resize(size + 64);
  text.resize(LLVMFuzzerMutate(reinterpret_cast<std::uint8_t*>(text.data()), size, text.size()));
  put(place, text);
}

void remove(const Place& place) {
  if (place.table != nullptr) {
    place.table->erase(place.key);
  } else {
    place.array->erase(place.array->cbegin() + static_cast<std::ptrdiff_t>(place.index));
  }
}

void copy_under(const Place& place, const std::vector<std::string>& keys, std::mt19937& rng) {
  if (place.table != nullptr) {
    place.table->insert_or_assign(keys[rng() % keys.size()], *place.node);
  } else {
    place.array->push_back(*place.node);
  }
}

}  // namespace

std::size_t mutate_toml(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned int seed) {
  std::mt19937 rng(seed);
  toml::table root;
  try {
    root = toml::parse(std::string_view(reinterpret_cast<const char*>(data), size));
  } catch (const toml::parse_error&) {
    return LLVMFuzzerMutate(data, size, max_size);
  }
  std::vector<Place> places;
  std::vector<std::string> keys;
  collect(root, places, keys);
  if (places.empty() || rng() % 8 == 0) return LLVMFuzzerMutate(data, size, max_size);
  const Place& place = places[rng() % places.size()];
  switch (rng() % 6) {
    case 0: boundary_value(place, rng); break;
    case 1: scale_number(place, rng); break;
    case 2: mutate_string(place, rng); break;
    case 3: remove(place); break;
    case 4: copy_under(place, keys, rng); break;
    default: boundary_value(place, rng); break;
  }
  std::ostringstream out;
  out << root;
  const std::string text = out.str();
  if (text.size() > max_size) return LLVMFuzzerMutate(data, size, max_size);
  std::memcpy(data, text.data(), text.size());
  return text.size();
}

}  // namespace tissue::fuzz
