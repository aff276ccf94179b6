#include "awcc/sha256.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "test_paths.hpp"

namespace {

std::string digest(const std::string& text) {
  awcc::Sha256 h;
  h.update({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
  return h.hex();
}

// The test vectors of FIPS 180-4 (NIST's examples), including the two-block
// message and the padding edge of 55/56/64 bytes.
TEST(Sha256, NistVectors) {
  EXPECT_EQ(digest(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(digest("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(digest("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(digest(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// Fed in pieces of every size, the digest is the same as in one piece.
TEST(Sha256, PiecesGiveTheSameDigest) {
  std::string text;
  for (int i = 0; i < 300; ++i) text += static_cast<char>(i * 7 + 3);
  const auto whole = digest(text);
  for (std::size_t piece : {1u, 3u, 55u, 56u, 63u, 64u, 65u, 200u}) {
    awcc::Sha256 h;
    for (std::size_t i = 0; i < text.size(); i += piece) {
      const auto n = std::min(piece, text.size() - i);
      h.update({reinterpret_cast<const std::uint8_t*>(text.data() + i), n});
    }
    EXPECT_EQ(h.hex(), whole) << piece;
  }
  const auto path = pdp_test::temp_dir() / "sha256.bin";
  std::ofstream(path, std::ios::binary) << text;
  EXPECT_EQ(awcc::sha256_of_file(path), whole);
}

}  // namespace
