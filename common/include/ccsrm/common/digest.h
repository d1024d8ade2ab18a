#pragma once
// 64-bit FNV-1a over bytes: a change of any byte changes the digest. It tells
// data apart (a journal record cut short, a checkpoint of other inputs); it
// is no defence against forgery.
#include <cstddef>
#include <cstdint>
#include <string>

namespace ccsrm {

class Fnv1aDigest {
 public:
  void Add(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      value_ ^= bytes[i];
      value_ *= 1099511628211ULL;
    }
  }
  std::uint64_t value() const { return value_; }
  // 16 lower-case hexadecimal digits.
  std::string Hex() const;

 private:
  std::uint64_t value_ = 14695981039346656037ULL;
};

}  // namespace ccsrm
