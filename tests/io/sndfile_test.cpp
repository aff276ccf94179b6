// The libsndfile reader (awcc/recording.hpp) on inputs the reader fuzz target
// (fuzz/fuzz_read.cpp) found mishandled; each file is built here byte by byte.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "awcc/recording.hpp"
#include "test_paths.hpp"

namespace {

std::vector<float> read_all(awcc::Recording& r, std::int64_t block) {
  std::vector<float> all, buffer(static_cast<std::size_t>(block * r.info().channels));
  for (std::int64_t n; (n = r.read(buffer, block)) > 0;) {
    all.insert(all.end(), buffer.begin(), buffer.begin() + n * r.info().channels);
  }
  return all;
}

void put_be32(std::string& s, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) s.push_back(static_cast<char>((v >> shift) & 0xFF));
}

// Found by fuzz_read_sndfile: a Sun AU file whose header gives its data offset
// as 0 (inside the header). libsndfile reads its data from after the 24-byte
// header, but sf_seek(0) went back to byte 0, so the second pass (rewind())
// read the header's bytes as samples: the two passes of processing (levels,
// then binarisation) saw different recordings. A second pass must hand out the
// first pass's samples.
TEST(Sndfile, ASecondPassReadsWhatTheFirstRead) {
  std::string au = ".snd";
  put_be32(au, 0);         // data offset: inside the header
  put_be32(au, 6163384);   // data size: more than there is
  put_be32(au, 1);         // 8-bit u-law
  put_be32(au, 10000);     // Hz
  put_be32(au, 66);        // channels
  // The fuzzer's 69 data bytes: one frame of 66 u-law samples and 3 more.
  const unsigned char data[] = {
      0x85, 0x3a, 0xbf, 0x85, 0xbf, 0x85, 0x85, 0x85, 0x85, 0x85, 0x13, 0xbf, 0x85, 0xbf, 0x85, 0x85, 0x85, 0x85,
      0x85, 0x85, 0xbf, 0xbf, 0xbf, 0xbf, 0xbf, 0xbf, 0xbf, 0xf8, 0xbf, 0xbf, 0xbf, 0xbf, 0xbf, 0xbf, 0xbf, 0xbf,
      0x00, 0x00, 0x61, 0x10, 0xbf, 0x4e, 0x53, 0x74, 0x36, 0x6c, 0x6f, 0x63, 0x61, 0x6c, 0x65, 0x35, 0xbf, 0xbf,
      0xbf, 0x85, 0xbf, 0x85, 0xbf, 0x85, 0xbf, 0x85, 0x85, 0xbf, 0x85, 0xbf, 0xbf, 0xbf, 0xbf};
  au.append(reinterpret_cast<const char*>(data), sizeof data);
  const auto p = pdp_test::test_file("offset0.au");
  std::ofstream(p, std::ios::binary).write(au.data(), static_cast<std::streamsize>(au.size()));
  auto r = awcc::open_recording(p, {});
  const auto first = read_all(*r, 4096);
  ASSERT_EQ(first.size(), 66u);
  r->rewind();
  EXPECT_EQ(read_all(*r, 4096), first);
}

}  // namespace
