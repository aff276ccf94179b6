#include "awcc/sha256.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "awcc/errors.hpp"
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

// The padding edges: a message of 55 bytes pads in its own block, 56 needs a
// second; 64 and 120 likewise one block on. References from Python's hashlib.
TEST(Sha256, PaddingEdges) {
  EXPECT_EQ(digest(std::string(55, 'a')), "9f4390f8d30c2dd92ec9f095b65e2b9ae9b0a925a5258e241c9f1e910f734318");
  EXPECT_EQ(digest(std::string(56, 'a')), "b35439a4ac6f0948b6d6f9e3c6af0f5f590ce20f1bde7090ef7970686ec6738a");
  EXPECT_EQ(digest(std::string(63, 'a')), "7d3e74a05d7db15bce4ad9ec0658ea98e3f06eeecf16b4c6fff2da457ddc2f34");
  EXPECT_EQ(digest(std::string(64, 'a')), "ffe054fe7ae0cb6dc65c3af9b61d5209f439851db43d0ba5997337df154668eb");
  EXPECT_EQ(digest(std::string(65, 'a')), "635361c48bb9eab14198e76ea8ab7f1a41685d6ad62aa9146d301d4f17eb0ae0");
  EXPECT_EQ(digest(std::string(119, 'a')), "31eba51c313a5c08226adf18d4a359cfdfd8d2e816b13f4af952f7ea6584dcfb");
  EXPECT_EQ(digest(std::string(120, 'a')), "2f3d335432c70b580af0e8e1b3674a7c020d683aa5f73aaaedfdc55af904c21c");
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

// A file's digest from the bytes a reader happens to read equals the whole
// file's, whatever the order: reads in sequence, reads overlapping the
// cursor, re-reads from the start, jumps ahead (a trailing chunk read before
// the data), and bytes never read at all, in 200 random orders.
TEST(Sha256, FileDigestFromReadsInAnyOrder) {
  std::mt19937 random(7);
  std::vector<std::uint8_t> bytes(100000);
  for (auto& b : bytes) b = static_cast<std::uint8_t>(random());
  const auto path = pdp_test::temp_dir() / "sha256_reads.bin";
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(bytes.size()));
  const std::string whole = awcc::sha256_of_file(path);
  for (int trial = 0; trial < 200; ++trial) {
    // Half the trials with room for every copy, half with room for one read's
    // (the hashing thread then reads what was not copied from the file).
    awcc::FileSha256 h(path, trial % 2 ? std::size_t{1} << 20 : 9000);
    const int reads = static_cast<int>(random() % 40);
    std::uint64_t at = 0;
    for (int r = 0; r < reads; ++r) {
      switch (random() % 4) {
        case 0: at = 0; break;                                   // rewind
        case 1: at = random() % bytes.size(); break;             // seek anywhere
        default: break;                                          // carry on
      }
      const std::uint64_t n = std::min<std::uint64_t>(random() % 9000, bytes.size() - at);
      h.saw(at, std::span<const std::uint8_t>(bytes).subspan(static_cast<std::size_t>(at), static_cast<std::size_t>(n)));
      at += n;
    }
    ASSERT_LE(h.seen(), bytes.size());
    EXPECT_EQ(h.hex(), whole) << "trial " << trial;
  }
  // Read front to back with room for the copies, the file is not read again.
  awcc::FileSha256 sequential(path, bytes.size());
  for (std::size_t i = 0; i < bytes.size(); i += 4096) {
    sequential.saw(i, std::span<const std::uint8_t>(bytes).subspan(i, std::min<std::size_t>(4096, bytes.size() - i)));
  }
  EXPECT_EQ(sequential.seen(), bytes.size());
  EXPECT_EQ(sequential.hex(), whole);
  EXPECT_EQ(sequential.read_again(), 0u);
  // A reader that skips an 8-byte header (a UQ .dat) leaves nothing either:
  // the short gap is read when the first data are seen.
  awcc::FileSha256 skipping(path, bytes.size());
  for (std::size_t i = 8; i < bytes.size(); i += 4096) {
    skipping.saw(i, std::span<const std::uint8_t>(bytes).subspan(i, std::min<std::size_t>(4096, bytes.size() - i)));
  }
  EXPECT_EQ(skipping.seen(), bytes.size());
  EXPECT_EQ(skipping.hex(), whole);
  EXPECT_EQ(skipping.read_again(), 8u);
}

// A digest abandoned before hex() (a recording refused halfway through its
// reading) stops its hashing thread without reading the rest of the file.
TEST(Sha256, AbandonedDigestStops) {
  const auto path = pdp_test::temp_dir() / "sha256_abandoned.bin";
  const std::string text(1 << 20, 'y');
  std::ofstream(path, std::ios::binary) << text;
  for (int i = 0; i < 20; ++i) {
    awcc::FileSha256 h(path, i % 2 ? text.size() : 100);
    h.saw(0, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size() / 2});
  }
  awcc::FileSha256 whole(path);
  EXPECT_EQ(whole.hex(), awcc::sha256_of_file(path));
}

// Bytes hashed that the file no longer holds (it was cut while being read) are refused, not hashed as a shorter file.
TEST(Sha256, FileCutWhileReadIsRefused) {
  const auto path = pdp_test::temp_dir() / "sha256_cut.bin";
  const std::string text(5000, 'x');
  std::ofstream(path, std::ios::binary) << text;
  awcc::FileSha256 h(path);
  h.saw(0, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
  std::filesystem::resize_file(path, 1000);
  EXPECT_THROW(h.hex(), awcc::InputError);
}

// A file cut before the hashing thread reaches the bytes the reader saw
// beyond its in-flight room (so it reads them from the file, or hex() does)
// is refused, whichever of the two finds the end first.
TEST(Sha256, FileCutBeforeTheBytesNotCopiedAreReadIsRefused) {
  const auto path = pdp_test::temp_dir() / "sha256_cut_uncopied.bin";
  const std::string text(50000, 'z');
  for (int trial = 0; trial < 20; ++trial) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
    awcc::FileSha256 h(path, 100);
    std::filesystem::resize_file(path, 1000);
    h.saw(0, {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
    EXPECT_THROW(h.hex(), awcc::InputError) << "trial " << trial;
  }
}

// A large file read front to back with little room in flight: the hashing
// thread reads the bytes not copied, and ahead of the reader, and hex()
// finishes whatever it has not reached; every byte is hashed once, in
// order, whoever hashed it (an overlap or a hole changes the digest).
TEST(Sha256, ReadingAheadAndTakingOverGiveTheWholeDigest) {
  std::mt19937 random(11);
  std::vector<std::uint8_t> bytes(3 << 20);
  for (auto& b : bytes) b = static_cast<std::uint8_t>(random());
  const auto path = pdp_test::temp_dir() / "sha256_ahead.bin";
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(bytes.size()));
  const std::string whole = awcc::sha256_of_file(path);
  for (int trial = 0; trial < 12; ++trial) {
    awcc::FileSha256 h(path, std::size_t{1} << (12 + trial % 6));
    // Stop anywhere: after no read at all, halfway, or at the end.
    const std::size_t stop = trial % 3 == 0 ? 0 : (trial % 3 == 1 ? bytes.size() / 2 : bytes.size());
    for (std::size_t i = 0; i < stop; i += 65536) {
      h.saw(i, std::span<const std::uint8_t>(bytes).subspan(i, std::min<std::size_t>(65536, stop - i)));
    }
    EXPECT_EQ(h.hex(), whole) << "trial " << trial;
    EXPECT_LE(h.hashed_in_background(), bytes.size());
  }
}

}  // namespace
