// A block-sparse linear solve for the implicit step's islands: one block row per body (its six
// velocities, a seventh unknown where a grasp rule holds its rate about an axis), a block for each
// pair of bodies that share a contact point. Gaussian elimination by blocks, in the minimum-degree
// order of the bodies' contact graph (the fewest neighbours left first, ties to the lower index),
// with partial pivoting inside each diagonal block. Cost: a chain of n bodies (a tower) O(n) with
// no fill at all; a planar contact graph (a pyramid, boxes pressed side by side) about O(n^1.5);
// where dense LU costs O((6 n)^3) in either case. (Nested dissection by breadth-first level sets
// was tried and filled more than minimum degree on these graphs up to a thousand bodies.)
//
// Why blocks without pivoting across them: the island's matrix is M + h (h K + C) plus, for
// sliding points, the friction term mu g_n t n^T. Its symmetric part is positive definite while no
// point slides, so every block pivot of the elimination is nonsingular whatever the order; a
// sliding point makes it unsymmetric but only by mu times a block that the masses dominate at the
// rates the engine runs. `solve` returns false when a pivot block is singular or not finite (the
// caller then falls back to the dense solve, dense_solve.hpp, which pivots across blocks).
//
// Use: reset(sizes), add_edge(i, j) for every pair in contact, analyse() (ordering and fill, once
// per structure), then per numeric system: clear(), add to diagonal(i), block(i, j), rhs(i);
// solve(). Buffers keep their capacity, so a structure no larger than one seen before allocates
// nothing. Deterministic: the order depends only on the structure and the node indices (ties to
// the lower index), never on a hash or an address.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace graspsim {

class BlockSparseSolver {
 public:
  static constexpr int kMaxBlock = 7;   // unknowns per node: 6, or 7 with an axis constraint

  // Room for `nodes` nodes with about `neighbours` each (fill included), so that structures within
  // it allocate nothing.
  void reserve(int nodes, int neighbours);

  // Starts a new structure of `sizes.size()` nodes, node i holding sizes[i] unknowns (1..7).
  void reset(const std::vector<int>& sizes);
  // Declares that nodes i != j are coupled (both blocks (i, j) and (j, i) may be nonzero).
  // Repeats are allowed.
  void add_edge(int i, int j);
  // The elimination order and the fill it creates; the numeric storage, zeroed.
  void analyse();

  // Zeroes every block and the right side, keeping the structure.
  void clear();
  // Row-major blocks, `size(i) x size(j)` (stride size(j)), valid after analyse(): the diagonal
  // block of i, the off-diagonal block (i, j) of an edge declared, and i's part of the right side.
  double* diagonal(int i) { return values_.data() + diagonal_[i]; }
  double* block(int i, int j);
  double* rhs(int i) { return rhs_.data() + offset_[i]; }
  int size(int i) const { return size_[i]; }

  // Solves in place: rhs(i) becomes node i's part of the solution. False when a pivot block is
  // singular or a value not finite (the right side is then left undefined). factor() then
  // substitute(rhs) is the same in two parts: the factors kept, later right sides solved by
  // substitution alone (`x`: a vector laid out as the right side, overwritten by the solution).
  bool solve();
  bool factor();
  bool substitute(double* x) const;
  bool factored() const { return factored_; }
  // y = A x with the blocks as assembled (before factor()); x and y laid out as the right side.
  void multiply(const double* x, double* y) const;
  // The blocks of `other`, which has the same structure (the same sizes and edges, analysed).
  void copy_values(const BlockSparseSolver& other);
  std::size_t unknowns() const { return rhs_.size(); }

  // For tests and the benchmark: blocks stored after analyse() (with fill), and the order.
  std::size_t stored_blocks() const { return stored_blocks_; }
  // Block updates (B_ij -= B_ik W_kj, each about 2 x 6^3 flops) one solve makes.
  std::size_t block_updates() const { return updates_.size(); }
  const std::vector<int>& order() const { return order_; }

 private:
  struct Entry {
    int node;        // the other node
    int value;       // offset of block (this, node) in values_
  };
  int find_entry(int i, int j) const;   // offset of block (i, j), -1 when not stored
  void order_by_minimum_degree(int begin, int end);
  void eliminate_symbolic();
  void symbolic_fill();
  void join_neighbours(int k, int u);   // eliminating k: u joins k's neighbours
  bool factor_block(int k);

  int n_ = 0;
  std::vector<int> size_, offset_;             // per node: unknowns, offset into rhs_
  std::vector<std::vector<int>> graph_;        // per node: declared neighbours (sorted, unique after analyse)
  std::vector<int> order_, position_;          // elimination order; node -> its place in it
  // Per node, after analyse: the blocks of its row with nodes eliminated after it (fill
  // included), sorted by node; the same nodes' blocks in its column are at the mirror entries.
  std::vector<std::vector<Entry>> upper_, lower_;
  std::vector<int> diagonal_;                  // per node: offset of its diagonal block
  std::vector<double> values_;                 // every block, row-major
  std::vector<double> rhs_;
  std::vector<int> pivots_;                    // per node, kMaxBlock each: the row swaps of its LU
  std::vector<int> updates_;                   // offsets of the blocks each elimination updates
  std::vector<int> update_begin_;              // per node: its first entry in updates_
  std::size_t stored_blocks_ = 0;
  bool factored_ = false;
  // Scratch for the ordering.
  std::vector<std::vector<int>> adjacency_;
  std::vector<int> degree_, mark_;
  int stamp_ = 0;
  std::vector<std::pair<int, int>> heap_;      // (-degree, -node): the next node to eliminate on top
  std::vector<int> merged_;
  std::vector<int> part_;                      // the nodes being ordered
};

}  // namespace graspsim
