#include "quadratic_program.h"

#include <Eigen/Cholesky>
#include <Eigen/Jacobi>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace leglab {
namespace {

using Index = Eigen::Index;
using SparseRows = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// A row whose component outside the working set's span is below this fraction of its norm is
// taken as dependent on the working set.
constexpr double kDependent = 1e-12;
// A row blocks a step only if its rate along the step exceeds this fraction of |row| |step|
// (in y coordinates): a smaller rate is rounding on a row the working set already implies.
// Larger than kDependent, so that a blocking row is never refused as dependent.
constexpr double kBlockingRate = 1e-11;
// A null-space step below this fraction of the gradient is zero: x minimises on the subspace.
constexpr double kZeroStep = 1e-12;
// A multiplier (times its row's norm) above -kNegative * (the gradient's scale) counts as >= 0.
constexpr double kNegative = 1e-12;

[[noreturn]] void Fail(const std::string& what) {
  throw std::invalid_argument("quadratic program: " + what);
}

// The working set's rows W (in y coordinates, as columns) factored as W = Q [R; 0]: Q n x n
// orthogonal, R upper triangular in its first size() columns. The first size() columns of Q
// span the rows, the others their null space.
class WorkingSetQr {
 public:
  explicit WorkingSetQr(Index n)
      : q_(Eigen::MatrixXd::Identity(n, n)), r_(Eigen::MatrixXd::Zero(n, n)) {}

  Index size() const { return size_; }

  // Appends `row` as the last column; returns false, changing nothing, if it is (numerically)
  // a combination of the rows present.
  bool Append(const Eigen::VectorXd& row) {
    const Index n = q_.rows();
    Eigen::VectorXd w = q_.transpose() * row;
    if (size_ >= n || w.tail(n - size_).norm() <= kDependent * row.norm()) return false;
    // Rotate the null-space part of w onto its first entry, from the bottom up.
    for (Index k = n - 1; k > size_; --k) {
      if (w[k] == 0.0) continue;
      Eigen::JacobiRotation<double> rotation;
      double top = 0.0;
      rotation.makeGivens(w[k - 1], w[k], &top);
      w[k - 1] = top;
      w[k] = 0.0;
      q_.applyOnTheRight(k - 1, k, rotation);
    }
    r_.col(size_).head(size_ + 1) = w.head(size_ + 1);
    ++size_;
    return true;
  }

  // Removes column k; the columns after it move one place left.
  void Remove(Index k) {
    assert(k >= 0 && k < size_);
    for (Index j = k; j + 1 < size_; ++j) r_.col(j).head(j + 2) = r_.col(j + 1).head(j + 2);
    r_.col(size_ - 1).setZero();
    --size_;
    // Moving the columns left leaves R upper Hessenberg from column k: one rotation per column
    // brings it back to triangular.
    for (Index j = k; j < size_; ++j) {
      if (r_(j + 1, j) == 0.0) continue;
      Eigen::JacobiRotation<double> rotation;
      double diagonal = 0.0;
      rotation.makeGivens(r_(j, j), r_(j + 1, j), &diagonal);
      auto rows = r_.block(j, j + 1, 2, size_ - j - 1);
      rows.applyOnTheLeft(0, 1, rotation.transpose());
      r_(j, j) = diagonal;
      r_(j + 1, j) = 0.0;
      q_.applyOnTheRight(j, j + 1, rotation);
    }
  }

  // The minimiser p of 0.5 |p|^2 + gradient' p with W' p = 0: minus the gradient's
  // projection onto the null space of the rows.
  Eigen::VectorXd NullSpaceStep(const Eigen::VectorXd& gradient) const {
    const auto null_space = q_.rightCols(q_.cols() - size_);
    return -(null_space * (null_space.transpose() * gradient));
  }

  // The least-squares lambda of W lambda = -gradient (exact at a minimiser on the subspace).
  Eigen::VectorXd Multipliers(const Eigen::VectorXd& gradient) const {
    Eigen::VectorXd lambda = -(q_.leftCols(size_).transpose() * gradient);
    r_.topLeftCorner(size_, size_).triangularView<Eigen::Upper>().solveInPlace(lambda);
    return lambda;
  }

 private:
  Eigen::MatrixXd q_;
  Eigen::MatrixXd r_;
  Index size_ = 0;
};

void Validate(const QuadraticProgram& qp, const SparseRows& a, const Eigen::VectorXd& start) {
  const Index n = qp.hessian.rows();
  if (n < 1 || qp.hessian.cols() != n) Fail("the Hessian must be square and non-empty");
  if (qp.gradient.size() != n || a.cols() != n || start.size() != n) {
    std::ostringstream msg;
    msg << "sizes differ: Hessian " << n << " x " << n << ", gradient " << qp.gradient.size()
        << ", constraint columns " << a.cols() << ", start " << start.size();
    Fail(msg.str());
  }
  if (qp.bounds.size() != a.rows()) {
    Fail("constraints have " + std::to_string(a.rows()) + " rows but there are " +
         std::to_string(qp.bounds.size()) + " bounds");
  }
  const Eigen::Map<const Eigen::VectorXd> values(a.valuePtr(), a.nonZeros());
  if (!qp.hessian.allFinite() || !qp.gradient.allFinite() || !values.allFinite() ||
      !qp.bounds.allFinite() || !start.allFinite()) {
    Fail("the program and the start must be finite");
  }
}

// Throws unless `start` satisfies every row of A x <= b to within 1e-9 (1 + |b_i|).
void RequireFeasible(const SparseRows& a, const Eigen::VectorXd& b, const Eigen::VectorXd& start) {
  const Eigen::VectorXd violation = a * start - b;
  for (Index i = 0; i < a.rows(); ++i) {
    if (violation[i] > 1e-9 * (1.0 + std::abs(b[i]))) {
      std::ostringstream msg;
      msg << "the start violates constraint row " << i << " by " << violation[i];
      Fail(msg.str());
    }
  }
}

// The primal active-set iteration of SolveQuadraticProgram on one program, in the coordinates
// y = L'x (H = LL'), where the objective is 0.5 |y|^2 + (L^-1 g)'y and row i is
// (L^-1 a_i)'y <= b_i. Its methods are the iteration's steps.
class ActiveSetIteration {
 public:
  // `a` is the program's A, compressed; `cholesky` H's factor; `start` feasible.
  ActiveSetIteration(const QuadraticProgram& qp, const SparseRows& a,
                     const Eigen::LLT<Eigen::MatrixXd>& cholesky, const Eigen::VectorXd& start)
      : qp_(qp),
        a_(a),
        cholesky_(cholesky),
        n_(qp.hessian.rows()),
        m_(a.rows()),
        row_norm_in_y_(static_cast<size_t>(m_), -1.0),
        x_(start),
        in_working_(static_cast<size_t>(m_), 0),
        qr_(n_) {
    gradient_y_ = ExactGradientY();
  }

  // What a step towards the minimiser on the working set's subspace did.
  enum class Move { kNone, kReachedMinimum, kBlocked };

  // Moves towards the subspace minimiser until the first row outside the working set, which
  // then joins it. kNone (x unchanged) when x already minimises on the subspace.
  Move StepInSubspace() {
    const Eigen::VectorXd step_y = qr_.NullSpaceStep(gradient_y_);
    const double step_norm = step_y.norm();
    if (step_norm <= kZeroStep * gradient_y_.norm()) return Move::kNone;
    const Eigen::VectorXd step = cholesky_.matrixU().solve(step_y);
    const Eigen::VectorXd rate = a_ * step;
    const Eigen::VectorXd slack = qp_.bounds - a_ * x_;
    double length = 1.0;
    Index blocking = -1;
    for (Index i = 0; i < m_; ++i) {
      if (in_working_[static_cast<size_t>(i)] || rate[i] <= 0.0) continue;
      if (rate[i] <= kBlockingRate * NormInY(i) * step_norm) continue;
      const double room = std::max(0.0, slack[i]) / rate[i];
      if (room < length) {
        length = room;
        blocking = i;
      }
    }
    x_ += length * step;
    gradient_y_ += length * step_y;
    if (blocking < 0) return Move::kReachedMinimum;
    // The step moves along the working set and into the blocking row, so the row is
    // independent of the working set (kBlockingRate > kDependent).
    if (!qr_.Append(RowInY(blocking))) {
      throw std::logic_error("quadratic program: a blocking row was dependent");
    }
    working_.push_back(static_cast<int>(blocking));
    in_working_[static_cast<size_t>(blocking)] = 1;
    return Move::kBlocked;
  }

  // At a subspace minimum, with the gradient made exact again: the multipliers of the working
  // rows, and the position in the working set of the most negative one (times its row's norm),
  // or -1 when none is below -kNegative times the scale: then x is optimal.
  Index MostNegativeMultiplier() {
    gradient_y_ = ExactGradientY();
    lambda_ = qr_.Multipliers(gradient_y_);
    double scale = gradient_y_.norm();
    Index most_negative = -1;
    double most_negative_value = 0.0;
    for (Index k = 0; k < qr_.size(); ++k) {
      const double weighted = lambda_[k] * NormInY(working_[static_cast<size_t>(k)]);
      scale = std::max(scale, std::abs(weighted));
      if (weighted < most_negative_value) {
        most_negative_value = weighted;
        most_negative = k;
      }
    }
    if (most_negative < 0 || most_negative_value >= -kNegative * scale) return -1;
    return most_negative;
  }

  // Drops the working row at position k, which frees a descent direction.
  void Drop(Index k) {
    qr_.Remove(k);
    in_working_[static_cast<size_t>(working_[static_cast<size_t>(k)])] = 0;
    working_.erase(working_.begin() + k);
  }

  // The solution at an optimal x, after `iterations` iterations.
  QpSolution Solution(long iterations) const {
    QpSolution solution;
    solution.x = x_;
    solution.multipliers = Eigen::VectorXd::Zero(m_);
    for (Index k = 0; k < qr_.size(); ++k) {
      solution.multipliers[working_[static_cast<size_t>(k)]] = std::max(0.0, lambda_[k]);
    }
    solution.active_set = working_;
    solution.iterations = static_cast<int>(iterations);
    return solution;
  }

 private:
  // Row i of A in y coordinates, L^-1 a_i.
  Eigen::VectorXd RowInY(Index i) const {
    Eigen::VectorXd row = Eigen::VectorXd::Zero(n_);
    for (SparseRows::InnerIterator it(a_, i); it; ++it) row[it.col()] = it.value();
    return Eigen::VectorXd(cholesky_.matrixL().solve(row));
  }
  // |L^-1 a_i|, computed when first needed.
  double NormInY(Index i) {
    double& norm = row_norm_in_y_[static_cast<size_t>(i)];
    if (norm < 0.0) norm = RowInY(i).norm();
    return norm;
  }
  // The objective's gradient in y, L^-1 (H x + g): exact at the start and before every
  // multiplier test, moved with y in between (a step changes it by the step).
  Eigen::VectorXd ExactGradientY() const {
    return Eigen::VectorXd(
        cholesky_.matrixL().solve(qp_.hessian.selfadjointView<Eigen::Lower>() * x_ + qp_.gradient));
  }

  const QuadraticProgram& qp_;
  const SparseRows& a_;
  const Eigen::LLT<Eigen::MatrixXd>& cholesky_;
  Index n_;
  Index m_;
  std::vector<double> row_norm_in_y_;  // -1 until computed
  Eigen::VectorXd x_;
  Eigen::VectorXd gradient_y_;
  Eigen::VectorXd lambda_;    // the working rows' multipliers at the last test
  std::vector<int> working_;  // rows, in the order of the factorisation's columns
  std::vector<char> in_working_;
  WorkingSetQr qr_;
};

}  // namespace

QpSolution SolveQuadraticProgram(const QuadraticProgram& qp,
                                 const Eigen::VectorXd& feasible_start) {
  SparseRows a = qp.constraints;
  a.makeCompressed();
  Validate(qp, a, feasible_start);
  const Eigen::LLT<Eigen::MatrixXd> cholesky(qp.hessian);
  if (cholesky.info() != Eigen::Success) Fail("the Hessian must be positive definite");
  RequireFeasible(a, qp.bounds, feasible_start);

  ActiveSetIteration method(qp, a, cholesky, feasible_start);
  bool at_subspace_minimum = false;
  const long max_iterations =
      20 * (static_cast<long>(qp.hessian.rows()) + static_cast<long>(a.rows())) + 100;
  for (long iteration = 1; iteration <= max_iterations; ++iteration) {
    if (!at_subspace_minimum) {
      const ActiveSetIteration::Move move = method.StepInSubspace();
      if (move != ActiveSetIteration::Move::kNone) {
        at_subspace_minimum = move == ActiveSetIteration::Move::kReachedMinimum;
        continue;
      }
    }
    // x minimises the objective with the working rows as equalities: optimal unless a
    // multiplier is negative; then drop the most negative row.
    const Index most_negative = method.MostNegativeMultiplier();
    if (most_negative < 0) return method.Solution(iteration);
    method.Drop(most_negative);
    at_subspace_minimum = false;
  }
  throw std::runtime_error("quadratic program: no solution after " +
                           std::to_string(max_iterations) +
                           " active-set iterations (cycling on a degenerate program)");
}

}  // namespace leglab
