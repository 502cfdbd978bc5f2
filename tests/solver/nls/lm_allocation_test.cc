// LevenbergMarquardt::solve() allocates nothing per iteration (docs/STYLE.md "Hot
// paths allocate nothing"). This file replaces malloc & co. for the whole
// test binary (glibc allows it: define malloc, free, calloc, realloc and the
// aligned variants, forward to __libc_*) and operator new/delete, and counts
// calls while a switch is on. The progress callback runs inside the
// iteration loop, so the count between its first and last call is what the
// loop allocated, including CHOLMOD's refactorisations and solves.
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <new>

#include <gtest/gtest.h>

#include "lm_test_factors.h"
#include "solver/nls/dense_damped_solver.h"
#include "solver/nls/levenberg_marquardt.h"

#if defined(__SANITIZE_ADDRESS__)
#define CDPR_COUNT_ALLOCATIONS 0  // the sanitizer owns malloc
#else
#define CDPR_COUNT_ALLOCATIONS 1
#endif

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};  // malloc-family calls and frees while counting
[[maybe_unused]] void note() {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

#if CDPR_COUNT_ALLOCATIONS
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t n) noexcept {
  note();
  return __libc_malloc(n);
}
void* calloc(std::size_t count, std::size_t n) noexcept {
  note();
  return __libc_calloc(count, n);
}
void* realloc(void* p, std::size_t n) noexcept {
  note();
  return __libc_realloc(p, n);
}
void free(void* p) noexcept {
  if (p != nullptr) note();
  __libc_free(p);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) noexcept {
  note();
  return __libc_memalign(alignment, n);
}
void* memalign(std::size_t alignment, std::size_t n) noexcept {
  note();
  return __libc_memalign(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) noexcept {
  note();
  *out = __libc_memalign(alignment, n);
  return *out != nullptr ? 0 : ENOMEM;
}
}  // extern "C"

// operator new/delete through the counted functions above (libstdc++'s own
// would too; replacing them makes the count independent of that detail).
void* operator new(std::size_t n) {
  if (void* p = std::malloc(n != 0 ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void* operator new(std::size_t n, std::align_val_t a) {
  const std::size_t alignment = static_cast<std::size_t>(a);
  if (void* p = aligned_alloc(alignment, (n + alignment - 1) / alignment * alignment)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n, std::align_val_t a) { return operator new(n, a); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
#endif

namespace cdpr {
namespace {

// 100 poses on a grid under 4 cables, each with a pose prior, 4 range
// factors (Huber, with gross outliers) and, when `link_poses`, a
// relative-pose factor, started off the truth; plus one log factor whose
// first undamped step leaves its domain, so the loop also runs through
// refused and rejected candidates. Linked poses make the solver factorise
// the whole J^T J; without the links it eliminates the poses first.
Problem realistic_problem(int* refusals, bool link_poses, Loss loss) {
  const std::array<Eigen::Vector3d, 4> anchors = {
      Eigen::Vector3d(0, 0, 20), Eigen::Vector3d(30, 0, 21), Eigen::Vector3d(30, 25, 19), Eigen::Vector3d(0, 25, 20)};
  const std::array<Eigen::Vector3d, 4> attachments = {
      Eigen::Vector3d(-0.4, -0.3, 0.2), Eigen::Vector3d(0.4, -0.3, 0.2), Eigen::Vector3d(0.4, 0.3, 0.2),
      Eigen::Vector3d(-0.4, 0.3, 0.2)};
  Problem problem;
  std::vector<Pose> truth;
  for (int k = 0; k < 100; ++k) {
    Pose p;
    p.position_world = Eigen::Vector3d(5 + 2.0 * (k % 10), 4 + 1.7 * (k / 10), 3 + 0.3 * (k % 7));
    p.world_R_platform = so3_exp(Eigen::Vector3d(0.02 * (k % 5), -0.03 * (k % 3), 0.01 * k));
    truth.push_back(p);
    Pose start = p;
    start.position_world += Eigen::Vector3d(0.03, -0.02, 0.04);
    start.world_R_platform = start.world_R_platform * so3_exp(Eigen::Vector3d(0.01, 0.02, -0.01));
    problem.add_pose(PoseKey(k), start);
  }
  for (int i = 0; i < 4; ++i) {
    problem.add_vector(AnchorKey(i), anchors[i] + Eigen::Vector3d(0.5, -0.4, 0.3));
    problem.add_vector(OffsetKey(i), Eigen::VectorXd::Constant(1, 0.2 * i));
  }
  for (int k = 0; k < 100; ++k) {
    problem.add_factor(std::make_unique<test::SE3PriorFactor>(PoseKey(k), truth[k], 0.01, 0.005));
    for (int i = 0; i < 4; ++i) {
      double encoder = (truth[k].transform(attachments[i]) - anchors[i]).norm() + 0.1 * i;
      if ((k * 4 + i) % 37 == 0) encoder += 0.5;  // outlier
      problem.add_factor(std::make_unique<test::RangeFactor>(PoseKey(k), AnchorKey(i), OffsetKey(i), attachments[i],
                                                             encoder, 0.002, loss));
    }
    if (link_poses && k > 0) {
      Pose a_T_b;
      a_T_b.position_world =
          truth[k - 1].world_R_platform.conjugate() * (truth[k].position_world - truth[k - 1].position_world);
      a_T_b.world_R_platform = truth[k - 1].world_R_platform.conjugate() * truth[k].world_R_platform;
      problem.add_factor(std::make_unique<test::SE3BetweenFactor>(PoseKey(k - 1), PoseKey(k), a_T_b, 0.01, 0.005));
    }
  }
  problem.add_vector(EffectKey(0), Eigen::VectorXd::Constant(1, 10.0));
  problem.add_factor(std::make_unique<test::LogFactor>(EffectKey(0), 0.001, 0.1, refusals));
  return problem;
}

// Solves with the allocation counter on; the count between the first and
// the last progress call is what the loop allocated.
void expect_loop_allocates_nothing(bool link_poses, LinearSystemKind expected_system, Loss loss = Loss{3.0}) {
  // GIVEN a realistic problem and a solver built for it (setup may allocate)
  int refusals = 0;
  Problem problem = realistic_problem(&refusals, link_poses, loss);
  long first = -1, last = -1;
  int calls = 0, rejected = 0;
  SolverOptions options;
  options.progress = [&](const IterationSummary& s) {
    const long now = g_allocations.load();
    if (first < 0) first = now;
    last = now;
    ++calls;
    rejected += s.iteration > 0 && !s.step_accepted;
  };
  LevenbergMarquardt lm(problem, options);
  ASSERT_EQ(lm.linear_system(), expected_system);
  // WHEN solving with the counter on
  g_allocations = 0;
  g_counting = true;
  const SolverSummary summary = lm.solve();
  g_counting = false;
  // THEN between the first and the last progress call nothing was allocated
  // or freed, over many iterations including rejected ones
  ASSERT_TRUE(summary.usable()) << summary.message;
  EXPECT_GE(calls, 6);
  EXPECT_GT(refusals, 0);
  EXPECT_GT(rejected, 0);
  EXPECT_EQ(last - first, 0) << "allocations inside the LM loop over " << calls - 1 << " iterations";
  // and the counter works: the same switch sees an allocation
  g_counting = true;
  const long before = g_allocations.load();
  std::vector<double>* probe = new std::vector<double>(100);
  delete probe;
  g_counting = false;
  EXPECT_GE(g_allocations.load() - before, 4);
}

TEST(LevenbergMarquardtAllocation, IterationLoopAllocatesNothing) {
  if (!CDPR_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocation counting is off under AddressSanitizer";
  expect_loop_allocates_nothing(true, LinearSystemKind::kFull);
}

TEST(LevenbergMarquardtAllocation, IterationLoopWithPosesEliminatedAllocatesNothing) {
  if (!CDPR_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocation counting is off under AddressSanitizer";
  expect_loop_allocates_nothing(false, LinearSystemKind::kPosesEliminated);
}

TEST(LevenbergMarquardtAllocation, IterationLoopWithASharedCauchyLossAllocatesNothing) {
  // The loss calibrate()'s robust stages switch between solves, read by the
  // factors at every evaluation.
  if (!CDPR_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocation counting is off under AddressSanitizer";
  const LossFunction cauchy{LossKind::kCauchy, 3.0};
  expect_loop_allocates_nothing(false, LinearSystemKind::kPosesEliminated, Loss{0.0, &cauchy});
}

TEST(DenseDampedSolverAllocation, FixedSizesAllocateNothing) {
  // The small solves of one pose run per row and per start: with fixed
  // sizes the whole solve, central differences and bounds included, stays
  // off the heap.
  if (!CDPR_COUNT_ALLOCATIONS) GTEST_SKIP() << "allocation counting is off under AddressSanitizer";
  // GIVEN Rosenbrock by central differences, one coordinate bounded
  DenseDampedOptions options;
  options.gain_tolerance = 1e-14;
  DenseDampedSolver<2, 2> solver(options);
  solver.set_bounds(Eigen::Vector2d(-5.0, -5.0), Eigen::Vector2d(0.9, 5.0));
  Eigen::Vector2d x(-1.2, 1.0);
  int evaluations = 0;
  auto rosenbrock = [&](const Eigen::Vector2d& at, Eigen::Vector2d& r) {
    ++evaluations;
    r << 10.0 * (at(1) - at(0) * at(0)), 1.0 - at(0);
    return true;
  };
  // WHEN minimised with the counter on
  g_allocations = 0;
  g_counting = true;
  const DenseDampedSummary summary = solver.minimize_numeric(x, rosenbrock);
  g_counting = false;
  // THEN it took many steps, ended on the bound, and allocated nothing
  EXPECT_GT(summary.accepted, 5);
  EXPECT_GT(evaluations, 20);
  EXPECT_EQ(x(0), 0.9);
  EXPECT_EQ(g_allocations.load(), 0);
}

}  // namespace
}  // namespace cdpr
