#include "awcc/sha256.hpp"

#include <fmt/format.h>
#include <openssl/evp.h>

#include <fstream>
#include <new>
#include <stdexcept>
#include <vector>

#include "awcc/errors.hpp"

namespace awcc {

struct Sha256::Context {
  EVP_MD_CTX* ctx;
};

void Sha256::Free::operator()(Context* c) const {
  EVP_MD_CTX_free(c->ctx);
  delete c;
}

Sha256::Sha256() : context_(new Context{EVP_MD_CTX_new()}) {
  if (!context_->ctx) throw std::bad_alloc();
  // Fails only when libcrypto has no SHA-256 at all (a FIPS provider
  // misconfigured): no digest can be trusted then.
  if (EVP_DigestInit_ex(context_->ctx, EVP_sha256(), nullptr) != 1) {
    throw std::runtime_error("libcrypto (OpenSSL) cannot compute SHA-256 here: check its installation");
  }
}

void Sha256::update(std::span<const std::uint8_t> data) {
  if (data.empty()) return;
  if (EVP_DigestUpdate(context_->ctx, data.data(), data.size()) != 1) {
    throw std::runtime_error("libcrypto (OpenSSL) failed while computing SHA-256");
  }
}

std::string Sha256::hex() {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  if (EVP_DigestFinal_ex(context_->ctx, digest, &size) != 1 || size != 32) {
    throw std::runtime_error("libcrypto (OpenSSL) failed while computing SHA-256");
  }
  std::string out;
  out.reserve(64);
  for (unsigned int i = 0; i < size; ++i) out += fmt::format("{:02x}", digest[i]);
  return out;
}

namespace {

// Hashes the file's bytes from `from` to its end into `digest`.
void hash_rest(const std::filesystem::path& path, std::uint64_t from, Sha256& digest) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot read the file to hash it", path.string()));
  if (from > 0) {
    // Bytes already hashed that the file no longer holds: it changed while being read.
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    in.seekg(static_cast<std::streamoff>(from));
    if (ec || size < from || !in) {
      throw InputError(fmt::format("{}: the file became shorter while being read; read it again when it is complete",
                                   path.string()));
    }
  }
  std::vector<char> buffer(std::size_t{1} << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const auto n = static_cast<std::size_t>(in.gcount());
    if (n > 0) digest.update({reinterpret_cast<const std::uint8_t*>(buffer.data()), n});
  }
  if (in.bad()) throw InputError(fmt::format("{}: a read error while hashing the file", path.string()));
}

}  // namespace

std::string sha256_of_file(const std::filesystem::path& path) {
  Sha256 h;
  hash_rest(path, 0, h);
  return h.hex();
}

FileSha256::FileSha256(std::filesystem::path path) : path_(std::move(path)) {}

void FileSha256::saw(std::uint64_t offset, std::span<const std::uint8_t> bytes) {
  const std::uint64_t end = offset + bytes.size();
  if (end <= hashed_) return;  // seen before (a second pass)
  if (offset > hashed_) {
    // A short gap (a header the reader skips, a chunk it steps over) is read
    // now, so that the cursor follows the reading; a long one (a trailing
    // chunk read before the data) is left for the reading to reach.
    if (offset - hashed_ > gap_read_now) return;
    std::ifstream in(path_, std::ios::binary);
    in.seekg(static_cast<std::streamoff>(hashed_));
    std::vector<char> gap(static_cast<std::size_t>(offset - hashed_));
    in.read(gap.data(), static_cast<std::streamsize>(gap.size()));
    if (in.gcount() != static_cast<std::streamsize>(gap.size())) return;  // hex() reads it, or says why not
    digest_.update({reinterpret_cast<const std::uint8_t*>(gap.data()), gap.size()});
    hashed_ = offset;
  }
  digest_.update(bytes.subspan(static_cast<std::size_t>(hashed_ - offset)));
  hashed_ = end;
}

std::string FileSha256::hex() {
  hash_rest(path_, hashed_, digest_);
  return digest_.hex();
}

}  // namespace awcc
