// The examples call the ampm library only through ampm.hpp (the C++17 wrapper of ampm.h):
// ampm::Material / PhaseParams / Particles builders, the P2gView / G2pView / ForceView grid-view
// builders, and ampm::p2g, g2p_update, node_range, force_prepare, force_apply, Kernels::ahat.
// This file fixes the scalar and names the few types every other file uses.
#pragma once

#include <ampm.hpp>

namespace host {

/// The scalar of every example (f64: the conservation checks of the tests are sharp in it).
using Real = double;
using Material = ampm::Material<Real>;
using Phase = ampm::PhaseParams<Real>;
constexpr unsigned kKernel = AMPM_KERNEL_QUADRATIC;  // 3 nodes per axis
constexpr int kGrid = AMPM_GRID_COLLOCATED;

inline const char* status_name(AmpmStatus s) { return ampm::status_name(s); }

}  // namespace host
