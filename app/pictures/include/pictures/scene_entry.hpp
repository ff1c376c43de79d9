#pragma once
// The scene cache's entry format (scene_cache.cpp reads and writes it; fuzzers and tests may too): a header (magic
// "HKSCENE\0", format kSceneCacheFormat as u32 LE, payload size as u64 LE), a BLAKE2b checksum of header and payload,
// and the payload: a CBOR map of every kept field of an ImageScene (scene_cache.hpp).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <sodium.h>

#include "pictures/image_scene.hpp"

namespace hk::app {

/// Header and checksum bytes before an entry's payload.
inline constexpr std::size_t kSceneEntryPrefixBytes = 8 + 4 + 8 + crypto_generichash_BYTES;

/// What is wrong with an entry (one phrase, after "entry '<path>' ").
struct BadEntry {
  std::string why;
};

/// Whether `k` is a scene key: 64 lowercase hexadecimal digits.
bool is_key(const std::string& k);

/// The whole entry file of `is` under `key`. @throws BadEntry or std::exception when it cannot be encoded.
std::vector<std::uint8_t> encode_entry(const std::string& key, const ImageScene& is);

/// The ImageScene of an entry file's bytes (its Scene not built), checked for magic, format, size,
/// checksum, a CBOR document within its value and depth budget, and the key it was stored under.
/// @throws BadEntry naming what is wrong.
ImageScene decode_entry(const std::vector<std::uint8_t>& bytes, const std::string& key);

}  // namespace hk::app
