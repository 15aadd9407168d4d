// PostureEvaluator::Evaluate into a reused PostureDynamics allocates nothing
// (issue #23). Its own executable: it counts every heap allocation of the
// process by interposing malloc and friends (Eigen allocates with malloc, not
// operator new), which must not disturb the other dynamics tests.
#include <atomic>
#include <cstdlib>
#include <random>

#include <gtest/gtest.h>

#include "robomach/dynamics/posture_dynamics.h"
#include "robomach/dynamics/tool_tip_frf.h"
#include "test_models.h"

// GCC says so with __SANITIZE_*__; clang before 17 only through __has_feature.
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define ROBOMACH_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || defined(__SANITIZE_MEMORY__) || \
    defined(ROBOMACH_SANITIZED)
#define ROBOMACH_COUNT_MALLOC 0  // the sanitizer owns malloc
#elif defined(__GLIBC__) && defined(__GNUC__)
#define ROBOMACH_COUNT_MALLOC 1
#else
#define ROBOMACH_COUNT_MALLOC 0
#endif

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

#if ROBOMACH_COUNT_MALLOC
extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
void* malloc(size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_malloc(n);
}
void* calloc(size_t n, size_t s) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_calloc(n, s);
}
void* realloc(void* p, size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_realloc(p, n);
}
int posix_memalign(void** p, size_t a, size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  *p = __libc_memalign(a, n);
  return *p ? 0 : 12;  // ENOMEM
}
void* aligned_alloc(size_t a, size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return __libc_memalign(a, n);
}
}
#endif

namespace robomach::dynamics {
namespace {

// The counter itself works: a vector's growth is seen.
TEST(PostureAllocation, CounterSeesAllocations) {
  if (!ROBOMACH_COUNT_MALLOC) GTEST_SKIP() << "malloc cannot be counted in this build (sanitizer or not glibc)";
  const long before = g_allocations.load();
  std::vector<double>* v = new std::vector<double>(1000);
  const long after = g_allocations.load();
  delete v;
  EXPECT_GE(after - before, 2);
}

// Second and later postures of the KR210 (six joints, no effect DOFs) into
// the same PostureDynamics: zero allocations, with every output asked for
// and with only M, J and modes.
TEST(PostureAllocation, ReusedOutputAllocatesNothing) {
  if (!ROBOMACH_COUNT_MALLOC) GTEST_SKIP() << "malloc cannot be counted in this build (sanitizer or not glibc)";
  const auto model = testing::Kr210();
  PostureEvaluator ev(model);
  std::mt19937 rng(3);
  std::vector<Eigen::VectorXd> qs;
  for (int i = 0; i < 20; ++i) qs.push_back(testing::RandomPosture(*model, rng));
  PostureOptions few;
  few.cartesian = false;
  few.jacobian_condition = false;
  few.static_compliance = false;
  few.modal_masses = false;
  few.damping_ratios = false;
  for (const PostureOptions& o : {PostureOptions{}, PostureOptions{false, true}, few}) {
    PostureDynamics d;
    ev.Evaluate(qs[0], o, &d);  // sizes the buffers
    const long before = g_allocations.load();
    for (size_t i = 1; i < qs.size(); ++i) ev.Evaluate(qs[i], o, &d);
    EXPECT_EQ(g_allocations.load() - before, 0) << "cartesian " << o.cartesian << " cond " << o.jacobian_condition;
    EXPECT_EQ(d.modes.size(), 6u);
  }
}

// The modal FRF into a reused vector allocates nothing either.
TEST(PostureAllocation, ReusedFrfBufferAllocatesNothing) {
  if (!ROBOMACH_COUNT_MALLOC) GTEST_SKIP() << "malloc cannot be counted in this build (sanitizer or not glibc)";
  const auto model = testing::Kr210();
  PostureEvaluator ev(model);
  Eigen::VectorXd q(6);
  q << 0.0, -1.5707963, 1.5707963, 0.0, 0.7853982, 0.0;
  const PostureDynamics d = ev.Evaluate(q);
  const Eigen::VectorXd f = Eigen::VectorXd::LinSpaced(2000, 0.5, 1000.0);
  std::vector<Eigen::Matrix3cd> H;
  ReceptanceModal(d, f, &H);
  const long before = g_allocations.load();
  ReceptanceModal(d, f, &H);
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(H.size(), 2000u);
}

}  // namespace
}  // namespace robomach::dynamics
