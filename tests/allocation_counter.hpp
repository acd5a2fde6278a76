#pragma once
// Counts every operator new of the process while a test asks: the allocation tests' executables
// replace the global operator new and delete with these. Include it in one source file of an
// executable only (it defines them), and give that executable no other test: the replacement
// holds for the whole process.
#include <cstdlib>
#include <new>

namespace skylane::test {

/// Whether this thread's allocations are counted now, and how many were.
inline thread_local bool counting_allocations = false;
inline thread_local long allocations = 0;

/// The allocations `work` makes on this thread.
template <class Work>
long allocationsOf(Work&& work) {
  allocations = 0;
  counting_allocations = true;
  work();
  counting_allocations = false;
  return allocations;
}

}  // namespace skylane::test

// Out of line, so that GCC does not pair an inlined std::free with a new-expression.
__attribute__((noinline)) void* operator new(std::size_t bytes) {
  if (skylane::test::counting_allocations) ++skylane::test::allocations;
  if (void* p = std::malloc(bytes == 0 ? 1 : bytes)) return p;
  throw std::bad_alloc();
}
__attribute__((noinline)) void operator delete(void* p) noexcept { std::free(p); }
__attribute__((noinline)) void operator delete(void* p, std::size_t) noexcept { std::free(p); }
