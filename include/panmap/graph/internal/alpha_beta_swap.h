#pragma once

#include <vector>

#include "panmap/graph/internal/semantic_energy.h"

namespace panmap {
namespace internal {

/// What alphaBetaSwap did.
struct SwapStats {
  int sweeps = 0;  ///< sweeps over all label pairs run
  int moves = 0;   ///< swap moves accepted (each strictly lowered E)
  int solved = 0;  ///< swap moves solved (the others were skipped as unchanged)
  /// Vertices whose switch cost a move computed, over all moves (the others were skipped as
  /// unable to switch, see alpha_beta_swap.cpp).
  long long costed = 0;
  /// With SwapSeeds::kEveryVertex: seeds (switch cost < 0) whose lower bound said they could
  /// not be one, which kBounded would have left out; 0 when the bound holds.
  long long bound_misses = 0;
};

/// How a move finds the vertices that may switch: `kBounded` skips those a lower bound on
/// their switch cost rules out, `kEveryVertex` computes every one's; both select the same
/// vertices, so the result is the same.
enum class SwapSeeds { kBounded, kEveryVertex };

/// Alpha-beta swap (Boykov, Veksler, Zabih 2001) from `labels` (label indices, updated in
/// place): sweeps over the label pairs (alpha < beta, ascending) and for each solves the
/// binary problem of the vertices labelled alpha or beta exactly by one min cut
/// (Boost Graph's boykov_kolmogorov_max_flow), keeping the result when it lowers E. Stops after a
/// sweep without improvement or after max_sweeps. Deterministic.
SwapStats alphaBetaSwap(const LabelProblem& problem, std::vector<int>& labels, int max_sweeps,
                        SwapSeeds seeds = SwapSeeds::kBounded);

}  // namespace internal
}  // namespace panmap
