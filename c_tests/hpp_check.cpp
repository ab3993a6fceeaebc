// Compiled (not linked) by hand or by a ctest compiler run with
//   -std=c++17 -fno-exceptions -Wall -Wextra -Wpedantic -Werror -Iinclude
// include/ampm.hpp must compile warning-free without exceptions (AMPM_HPP_EXCEPTIONS
// undefined) and instantiate its templates for every (scalar, dimension) pair.
#include "ampm.hpp"

template struct ampm::Kernels<float, 2>;
template struct ampm::Kernels<float, 3>;
template struct ampm::Kernels<double, 2>;
template struct ampm::Kernels<double, 3>;
template class ampm::Particles<float, 2>;
template class ampm::Particles<double, 3>;
template class ampm::P2gView<float, 3>;
template class ampm::G2pView<double, 2>;
template class ampm::ForceView<float, 2>;

int ampm_hpp_check(float* grid, float* x, float* v) {
  const AmpmNodeBox box = ampm::node_box<3>({0, 0, 0}, {4, 4, 4});
  ampm::Particles<float, 3> p(1);
  p.x(x).v(v);
  const auto view = ampm::P2gView<float, 3>::separate(box, grid, {grid, grid, grid});
  const auto s = ampm::p2g(ampm::Material<float>().mu(1), AMPM_KERNEL_QUADRATIC,
                           AMPM_GRID_COLLOCATED, 0.1f, 0.0f, p, view);
  return s.ok() ? 0 : static_cast<int>(s.code());
}
