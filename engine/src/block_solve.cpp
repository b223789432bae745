// Block-sparse Gaussian elimination (block_solve.hpp): minimum-degree order, symbolic fill, then
// right-looking elimination by blocks with the pivot blocks' own LU.
#include "graspsim/engine/block_solve.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <utility>

namespace graspsim {

void BlockSparseSolver::reserve(int nodes, int neighbours) {
  const std::size_t n = static_cast<std::size_t>(nodes), d = static_cast<std::size_t>(neighbours);
  for (std::vector<std::vector<int>>* lists : {&graph_, &adjacency_}) {
    if (lists->size() < n) lists->resize(n);
    for (std::vector<int>& l : *lists) l.reserve(d);
  }
  for (std::vector<std::vector<Entry>>* lists : {&upper_, &lower_}) {
    if (lists->size() < n) lists->resize(n);
    for (std::vector<Entry>& l : *lists) l.reserve(d);
  }
  for (std::vector<int>* v : {&size_, &offset_, &order_, &position_, &diagonal_, &degree_, &mark_, &part_,
                              &update_begin_}) {
    v->reserve(n + 1);
  }
  merged_.reserve(2 * d);
  heap_.reserve(n * (d + 1));
  rhs_.reserve(n * kMaxBlock);
  pivots_.reserve(n * kMaxBlock);
  values_.reserve(n * (1 + 2 * d) * kMaxBlock * kMaxBlock);
  updates_.reserve(n * d * d);
}

void BlockSparseSolver::reset(const std::vector<int>& sizes) {
  n_ = static_cast<int>(sizes.size());
  size_.assign(sizes.begin(), sizes.end());
  offset_.resize(n_);
  int total = 0;
  for (int i = 0; i < n_; ++i) {
    offset_[i] = total;
    total += size_[i];
  }
  rhs_.resize(static_cast<std::size_t>(total));
  if (static_cast<int>(graph_.size()) < n_) graph_.resize(n_);
  for (int i = 0; i < n_; ++i) graph_[i].clear();
}

void BlockSparseSolver::add_edge(int i, int j) {
  if (i == j) return;
  graph_[i].push_back(j);
  graph_[j].push_back(i);
}

// Minimum degree on the subgraph that part_[begin, end) induces (eliminate the node with the
// fewest neighbours left, ties to the lower index, joining its neighbours to each other), appended
// to order_.
void BlockSparseSolver::order_by_minimum_degree(int begin, int end) {
  ++stamp_;
  for (int q = begin; q < end; ++q) mark_[part_[q]] = stamp_;
  std::vector<std::pair<int, int>>& heap = heap_;
  heap.clear();
  for (int q = begin; q < end; ++q) {
    const int v = part_[q];
    std::vector<int>& av = adjacency_[v];
    av.clear();
    for (int w : graph_[v]) {
      if (mark_[w] == stamp_) av.push_back(w);
    }
    degree_[v] = static_cast<int>(av.size());
    heap.emplace_back(-degree_[v], -v);   // a max-heap of (-degree, -index): fewest, then lowest
  }
  std::make_heap(heap.begin(), heap.end());
  while (!heap.empty()) {
    std::pop_heap(heap.begin(), heap.end());
    const auto [neg_degree, neg_node] = heap.back();
    heap.pop_back();
    const int k = -neg_node;
    if (mark_[k] != stamp_ || -neg_degree != degree_[k]) continue;   // ordered, or a stale entry
    mark_[k] = 0;
    order_.push_back(k);
    const std::vector<int>& nk = adjacency_[k];
    for (int u : nk) {
      join_neighbours(k, u);
      const int degree = static_cast<int>(adjacency_[u].size());
      if (degree != degree_[u]) {
        degree_[u] = degree;
        heap.emplace_back(-degree_[u], -u);
        std::push_heap(heap.begin(), heap.end());
      }
    }
    adjacency_[k].clear();
  }
}

// Eliminating node k joins its neighbours: neighbour u's adjacency becomes the union of its own
// and k's, less u and k (both sorted, so a merge).
void BlockSparseSolver::join_neighbours(int k, int u) {
  const std::vector<int>& nk = adjacency_[k];
  merged_.clear();
  std::set_union(adjacency_[u].begin(), adjacency_[u].end(), nk.begin(), nk.end(), std::back_inserter(merged_));
  std::vector<int>& au = adjacency_[u];
  au.clear();
  for (int v : merged_) {
    if (v != u && v != k) au.push_back(v);
  }
}

// The fill of eliminating in order_: each node, when eliminated, joins the nodes left that it
// touches. Records each node's neighbours at its elimination: the blocks of its row and column
// with the nodes after it.
void BlockSparseSolver::eliminate_symbolic() {
  for (int i = 0; i < n_; ++i) {
    adjacency_[i].assign(graph_[i].begin(), graph_[i].end());
    position_[i] = -1;
  }
  for (std::size_t p = 0; p < order_.size(); ++p) position_[order_[p]] = static_cast<int>(p);
  for (int k : order_) {
    const std::vector<int>& nk = adjacency_[k];   // the nodes left that k touches, sorted
    upper_[k].clear();
    for (int j : nk) upper_[k].push_back(Entry{j, -1});
    for (int u : nk) {
      join_neighbours(k, u);
    }
    adjacency_[k].clear();
  }
}

// Storage for every block the elimination touches, and per node the offsets of the updates its
// elimination makes: for each pair (i, j) of its later neighbours, block (i, j) -= B_ik W_kj.
void BlockSparseSolver::symbolic_fill() {
  diagonal_.resize(n_);
  std::size_t values = 0;
  for (int k = 0; k < n_; ++k) {
    diagonal_[k] = static_cast<int>(values);
    values += static_cast<std::size_t>(size_[k] * size_[k]);
  }
  stored_blocks_ = static_cast<std::size_t>(n_);
  for (int k = 0; k < n_; ++k) {
    lower_[k].clear();
    for (Entry& e : upper_[k]) {   // block (k, j), then its mirror (j, k) in lower_[k]
      e.value = static_cast<int>(values);
      values += static_cast<std::size_t>(size_[k] * size_[e.node]);
      lower_[k].push_back(Entry{e.node, static_cast<int>(values)});
      values += static_cast<std::size_t>(size_[k] * size_[e.node]);
      stored_blocks_ += 2;
    }
  }
  values_.assign(values, 0.0);
  if (pivots_.size() < static_cast<std::size_t>(n_ * kMaxBlock)) pivots_.resize(static_cast<std::size_t>(n_ * kMaxBlock));
  // The update targets: for k's later neighbours i, j (both sorted by node), the block (i, j)
  // is stored at row i (if i comes first) or in j's column (if j comes first), or is i's diagonal.
  updates_.clear();
  update_begin_.assign(n_ + 1, 0);
  for (int k = 0; k < n_; ++k) {
    update_begin_[k] = static_cast<int>(updates_.size());
    for (const Entry& ei : lower_[k]) {
      for (const Entry& ej : upper_[k]) updates_.push_back(ei.node == ej.node ? diagonal_[ei.node] : find_entry(ei.node, ej.node));
    }
  }
  update_begin_[n_] = static_cast<int>(updates_.size());
}

void BlockSparseSolver::analyse() {
  if (static_cast<int>(adjacency_.size()) < n_) {
    adjacency_.resize(n_);
    upper_.resize(n_);
    lower_.resize(n_);
  }
  degree_.resize(n_);
  position_.resize(n_);
  mark_.assign(n_, 0);
  stamp_ = 0;
  part_.resize(n_);
  for (int i = 0; i < n_; ++i) {
    std::vector<int>& g = graph_[i];
    std::sort(g.begin(), g.end());
    g.erase(std::unique(g.begin(), g.end()), g.end());
    part_[i] = i;
  }
  order_.clear();
  order_by_minimum_degree(0, n_);
  eliminate_symbolic();
  symbolic_fill();
  std::fill(rhs_.begin(), rhs_.end(), 0.0);
}

int BlockSparseSolver::find_entry(int i, int j) const {
  const bool row = position_[i] < position_[j];
  const std::vector<Entry>& list = row ? upper_[i] : lower_[j];
  const int other = row ? j : i;
  const auto it = std::lower_bound(list.begin(), list.end(), other, [](const Entry& e, int v) { return e.node < v; });
  return (it != list.end() && it->node == other) ? it->value : -1;
}

double* BlockSparseSolver::block(int i, int j) {
  const int at = find_entry(i, j);
  return at < 0 ? nullptr : values_.data() + at;
}

void BlockSparseSolver::clear() {
  factored_ = false;
  std::fill(values_.begin(), values_.end(), 0.0);
  std::fill(rhs_.begin(), rhs_.end(), 0.0);
}

// LU of node k's diagonal block in place, with partial pivoting (row swaps in pivots_).
bool BlockSparseSolver::factor_block(int k) {
  const int s = size_[k];
  double* a = diagonal(k);
  int* piv = pivots_.data() + static_cast<std::size_t>(k) * kMaxBlock;
  double scale = 0.0;
  for (int i = 0; i < s * s; ++i) scale = std::max(scale, std::abs(a[i]));
  if (!(scale > 0.0) || !std::isfinite(scale)) return false;
  for (int c = 0; c < s; ++c) {
    int p = c;
    for (int r = c + 1; r < s; ++r) {
      if (std::abs(a[r * s + c]) > std::abs(a[p * s + c])) p = r;
    }
    piv[c] = p;
    if (p != c) {
      for (int m = 0; m < s; ++m) std::swap(a[c * s + m], a[p * s + m]);
    }
    const double pivot = a[c * s + c];
    if (!(std::abs(pivot) > 1e-300 + 1e-14 * scale)) return false;
    for (int r = c + 1; r < s; ++r) {
      const double l = a[r * s + c] / pivot;
      a[r * s + c] = l;
      if (l == 0.0) continue;
      for (int m = c + 1; m < s; ++m) a[r * s + m] -= l * a[c * s + m];
    }
  }
  return true;
}

namespace {

// x := D^-1 x for the columns of an s x w row-major block x (stride w), D's LU from factor_block.
void lu_apply(const double* lu, const int* piv, int s, double* x, int w) {
  for (int c = 0; c < s; ++c) {
    if (piv[c] != c) {
      for (int m = 0; m < w; ++m) std::swap(x[c * w + m], x[piv[c] * w + m]);
    }
  }
  for (int r = 1; r < s; ++r) {   // L y = P x, unit diagonal
    for (int c = 0; c < r; ++c) {
      const double l = lu[r * s + c];
      if (l == 0.0) continue;
      for (int m = 0; m < w; ++m) x[r * w + m] -= l * x[c * w + m];
    }
  }
  for (int r = s - 1; r >= 0; --r) {   // U z = y
    for (int c = r + 1; c < s; ++c) {
      const double u = lu[r * s + c];
      if (u == 0.0) continue;
      for (int m = 0; m < w; ++m) x[r * w + m] -= u * x[c * w + m];
    }
    const double d = lu[r * s + r];
    for (int m = 0; m < w; ++m) x[r * w + m] /= d;
  }
}

// c (si x sj) -= a (si x sk) b (sk x sj), all row-major.
void multiply_subtract(double* c, const double* a, const double* b, int si, int sk, int sj) {
  for (int r = 0; r < si; ++r) {
    for (int m = 0; m < sk; ++m) {
      const double x = a[r * sk + m];
      if (x == 0.0) continue;
      for (int col = 0; col < sj; ++col) c[r * sj + col] -= x * b[m * sj + col];
    }
  }
}

}  // namespace

bool BlockSparseSolver::factor() {
  // Elimination: node k's pivot block factored, its row turned into W_kj = D_k^-1 B_kj; every
  // later pair (i, j) of its neighbours loses B_ik W_kj. The column blocks B_ik are kept for the
  // substitution.
  factored_ = false;
  for (int k : order_) {
    if (!factor_block(k)) return false;
    const double* lu = diagonal(k);
    const int* piv = pivots_.data() + static_cast<std::size_t>(k) * kMaxBlock;
    const int sk = size_[k];
    for (const Entry& e : upper_[k]) lu_apply(lu, piv, sk, values_.data() + e.value, size_[e.node]);
    const int* target = updates_.data() + update_begin_[k];
    for (const Entry& ei : lower_[k]) {
      const double* b_ik = values_.data() + ei.value;   // stored as (k, i)'s mirror: block (i, k)
      const int si = size_[ei.node];
      for (const Entry& ej : upper_[k]) {
        multiply_subtract(values_.data() + *target++, b_ik, values_.data() + ej.value, si, sk, size_[ej.node]);
      }
    }
  }
  factored_ = true;
  return true;
}

bool BlockSparseSolver::substitute(double* x) const {
  // Forward: y_k = D_k^-1 r_k in elimination order, each later neighbour's right side losing
  // B_ik y_k. Back, last eliminated first: x_k = y_k - sum over later j of W_kj x_j.
  for (int k : order_) {
    const double* lu = values_.data() + diagonal_[k];
    const int* piv = pivots_.data() + static_cast<std::size_t>(k) * kMaxBlock;
    double* yk = x + offset_[k];
    lu_apply(lu, piv, size_[k], yk, 1);
    for (const Entry& ei : lower_[k]) multiply_subtract(x + offset_[ei.node], values_.data() + ei.value, yk, size_[ei.node], size_[k], 1);
  }
  for (int p = n_ - 1; p >= 0; --p) {
    const int k = order_[p];
    double* xk = x + offset_[k];
    for (const Entry& e : upper_[k]) multiply_subtract(xk, values_.data() + e.value, x + offset_[e.node], size_[k], size_[e.node], 1);
    for (int i = 0; i < size_[k]; ++i) {
      if (!std::isfinite(xk[i])) return false;
    }
  }
  return true;
}

bool BlockSparseSolver::solve() { return factor() && substitute(rhs_.data()); }

void BlockSparseSolver::multiply(const double* x, double* y) const {
  std::fill(y, y + rhs_.size(), 0.0);   // -A x accumulated, then negated
  for (int k = 0; k < n_; ++k) {
    const int sk = size_[k];
    double* yk = y + offset_[k];
    multiply_subtract(yk, values_.data() + diagonal_[k], x + offset_[k], sk, sk, 1);
    for (const Entry& e : upper_[k]) multiply_subtract(yk, values_.data() + e.value, x + offset_[e.node], sk, size_[e.node], 1);
    for (const Entry& e : lower_[k]) {   // block (e.node, k) into e.node's row
      multiply_subtract(y + offset_[e.node], values_.data() + e.value, x + offset_[k], size_[e.node], sk, 1);
    }
  }
  for (std::size_t i = 0; i < rhs_.size(); ++i) y[i] = -y[i];
}

void BlockSparseSolver::copy_values(const BlockSparseSolver& other) {
  std::copy(other.values_.begin(), other.values_.end(), values_.begin());
  factored_ = false;
}

}  // namespace graspsim
