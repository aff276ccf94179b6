#include "awcc/pdpsim_layout.hpp"

#include <fmt/format.h>
#include <hdf5.h>

namespace awcc::pdpsim {

std::string hdf5_says() {
  std::string what;
  H5Ewalk2(
      H5E_DEFAULT, H5E_WALK_UPWARD,
      [](unsigned n, const H5E_error2_t* e, void* data) -> herr_t {
        if (n == 0 && e && e->desc) *static_cast<std::string*>(data) = e->desc;
        return 0;
      },
      &what);
  H5Eclear2(H5E_DEFAULT);
  for (auto& c : what) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f) c = '?';
  }
  if (what.size() > 200) what = what.substr(0, 200) + "...";
  return what.empty() ? std::string() : fmt::format(" (HDF5: {})", what);
}

}  // namespace awcc::pdpsim
