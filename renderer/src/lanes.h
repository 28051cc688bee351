#pragma once
// The per-lane values of one path (a float per wavelength the path carries), with the element-wise
// operations the tracer needs (pbrt-v4's SampledSpectrum is the model), in two kinds:
//  - LaneArray<kN>: a VALUE, the path's own state (its throughput, spectral MIS's densities, a shadow
//    ray's transmittance, a collision's coefficients): inline storage of kCapacity floats (kN, or
//    spectral::BinLayout::kMaxBins for kN = 0), 64-byte aligned, of which the first size() are used.
//    Nothing is zeroed: a LaneArray(n) holds n undefined lanes until written (LaneArray(n, x) fills
//    them), and a copy copies the n used lanes only, so a 4 KB value costs what its lanes do.
//  - Lanes<kN> / ConstLanes<kN>: VIEWS (pointer + n) into a bigger array: a row of a [row][lane]
//    table (the material cache, the per-light result accumulators, the film's rows). Views never
//    own memory.
// kN > 0: the lane count is known at compile time (the one-lane tracer), kN = 0: at run time.
// Expressions mix both kinds and float scalars and are evaluated lane by lane exactly as written,
// left to right, with no reassociation: `out += w * k * T` stores out_i + (w_i·k)·T_i, the same
// float operations as the loop it replaces, whether out, w and T are values or views. Scalars must
// be float (no silent double arithmetic). An expression must not read what it is assigned to
// through another view of the same memory (write `w *= k`, not `w = w2 * k` with w2 aliasing w);
// reading it lane for lane (`w = w * k`) is fine.
#include <algorithm>
#include <concepts>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "prizma/render/partial_reduce.h"
#include "prizma/spectral/bin_layout.h"

namespace prizma::render {

template <int kN>
class ConstLanes;
template <int kN>
class Lanes;
template <int kN>
class LaneArray;

namespace lanes_detail {

template <class T>
struct IsLaneExpr : std::false_type {};
template <class T>
concept LaneExpr = IsLaneExpr<std::remove_cvref_t<T>>::value;
template <class T>
concept Operand = LaneExpr<T> || std::same_as<std::remove_cvref_t<T>, float>;

template <class T>
float at(const T& x, int i) {
  if constexpr (std::is_same_v<T, float>)
    return x;
  else
    return x[i];
}

struct Add {
  static float apply(float a, float b) { return a + b; }
};
struct Sub {
  static float apply(float a, float b) { return a - b; }
};
struct Mul {
  static float apply(float a, float b) { return a * b; }
};
struct Max {  // std::max(a, b): b only when a < b
  static float apply(float a, float b) { return std::max(a, b); }
};

template <class Op, class A, class B>
struct Binary {
  A a;
  B b;
  float operator[](int i) const { return Op::apply(at(a, i), at(b, i)); }
};
template <class Op, class A, class B>
struct IsLaneExpr<Binary<Op, A, B>> : std::true_type {};
template <class F, class A>
struct Map {
  F f;
  A a;
  float operator[](int i) const { return f(at(a, i)); }
};
template <class F, class A>
struct IsLaneExpr<Map<F, A>> : std::true_type {};
template <int kN>
struct IsLaneExpr<ConstLanes<kN>> : std::true_type {};
template <int kN>
struct IsLaneExpr<Lanes<kN>> : std::true_type {};
template <int kN>
struct IsLaneExpr<LaneArray<kN>> : std::true_type {};

// Operands are held by value: views and expression nodes are a few pointers (a LaneArray by its view).
template <class T>
auto hold(const T& x) {
  if constexpr (std::is_same_v<T, float>)
    return x;
  else if constexpr (requires { x.view(); })
    return x.view();
  else
    return x;
}

template <class Op, class A, class B>
auto make(const A& a, const B& b) {
  return Binary<Op, decltype(hold(a)), decltype(hold(b))>{hold(a), hold(b)};
}

}  // namespace lanes_detail

// Read-only lanes.
template <int kN>
class ConstLanes {
 public:
  ConstLanes(const float* data, int n) : m_data(data), m_n(n) {}
  int size() const { return kN > 0 ? kN : m_n; }
  float operator[](int i) const { return m_data[i]; }
  const float* data() const { return m_data; }
  // Largest lane value and 0 (0 for no lanes; a NaN lane is never taken).
  float max() const { return partial::max_from_zero(m_data, size()); }
  // Σ lanes in lane order.
  float sum() const {
    float s = 0.0f;
    for (int i = 0; i < size(); ++i) s += m_data[i];
    return s;
  }

 private:
  const float* m_data;
  int m_n;
};

// Writable lanes.
template <int kN>
class Lanes {
 public:
  Lanes(float* data, int n) : m_data(data), m_n(n) {}
  Lanes(const Lanes&) = default;
  int size() const { return kN > 0 ? kN : m_n; }
  float& operator[](int i) const { return m_data[i]; }
  float* data() const { return m_data; }
  ConstLanes<kN> view() const { return ConstLanes<kN>(m_data, m_n); }
  operator ConstLanes<kN>() const { return view(); }
  float max() const { return view().max(); }
  float sum() const { return view().sum(); }

  template <lanes_detail::Operand E>
  const Lanes& operator=(const E& e) const {
    const auto x = lanes_detail::hold(e);
    for (int i = 0; i < size(); ++i) m_data[i] = lanes_detail::at(x, i);
    return *this;
  }
  const Lanes& operator=(const Lanes& other) const { return *this = other.view(); }
  template <lanes_detail::Operand E>
  const Lanes& operator+=(const E& e) const {
    const auto x = lanes_detail::hold(e);
    for (int i = 0; i < size(); ++i) m_data[i] += lanes_detail::at(x, i);
    return *this;
  }
  template <lanes_detail::Operand E>
  const Lanes& operator*=(const E& e) const {
    const auto x = lanes_detail::hold(e);
    for (int i = 0; i < size(); ++i) m_data[i] *= lanes_detail::at(x, i);
    return *this;
  }

 private:
  float* m_data;
  int m_n;
};

// A path's own lanes, by value (see the top of this file): n ≤ kCapacity lanes in inline storage,
// undefined until written. Assigning an expression, +=, *= and the reductions work on the n lanes
// as Lanes does; copying copies the n lanes (and the size).
template <int kN>
class alignas(64) LaneArray {
 public:
  static constexpr int kCapacity = kN > 0 ? kN : spectral::BinLayout::kMaxBins;

  // n lanes of undefined value (kN > 0: n must be kN). Throws std::length_error beyond kCapacity.
  explicit LaneArray(int n) : m_n(checked_size(n)) {}
  // n lanes, each x.
  LaneArray(int n, float x) : LaneArray(n) { lanes() = x; }
  LaneArray(const LaneArray& other) : m_n(other.m_n) { copy_from(other); }
  LaneArray& operator=(const LaneArray& other) {
    if (this != &other) {
      m_n = other.m_n;
      copy_from(other);
    }
    return *this;
  }
  // Every lane = e's lane (e's lane count is this one's).
  template <lanes_detail::Operand E>
  LaneArray& operator=(const E& e) {
    lanes() = e;
    return *this;
  }
  template <lanes_detail::Operand E>
  LaneArray& operator+=(const E& e) {
    lanes() += e;
    return *this;
  }
  template <lanes_detail::Operand E>
  LaneArray& operator*=(const E& e) {
    lanes() *= e;
    return *this;
  }

  int size() const { return kN > 0 ? kN : m_n; }
  float& operator[](int i) { return m_data[i]; }
  float operator[](int i) const { return m_data[i]; }
  float* data() { return m_data; }
  const float* data() const { return m_data; }
  // Views of the n lanes (for functions that write lanes wherever they are).
  Lanes<kN> lanes() { return Lanes<kN>(m_data, m_n); }
  ConstLanes<kN> view() const { return ConstLanes<kN>(m_data, m_n); }
  operator Lanes<kN>() { return lanes(); }
  operator ConstLanes<kN>() const { return view(); }
  float max() const { return view().max(); }
  float sum() const { return view().sum(); }

 private:
  static int checked_size(int n) {
    if (n < 0 || n > kCapacity || (kN > 0 && n != kN))
      throw std::length_error("LaneArray: " + std::to_string(n) + " lanes, capacity " + std::to_string(kCapacity));
    return n;
  }
  void copy_from(const LaneArray& other) {
    const int n = size();
    for (int i = 0; i < n; ++i) m_data[i] = other.m_data[i];
  }

  float m_data[kCapacity];  // uninitialised beyond what is written
  int m_n;
};

// Element-wise +, −, × and max of lanes, expressions and float scalars (at least one side lanes).
template <lanes_detail::Operand A, lanes_detail::Operand B>
  requires(lanes_detail::LaneExpr<A> || lanes_detail::LaneExpr<B>)
auto operator+(const A& a, const B& b) {
  return lanes_detail::make<lanes_detail::Add>(a, b);
}
template <lanes_detail::Operand A, lanes_detail::Operand B>
  requires(lanes_detail::LaneExpr<A> || lanes_detail::LaneExpr<B>)
auto operator-(const A& a, const B& b) {
  return lanes_detail::make<lanes_detail::Sub>(a, b);
}
template <lanes_detail::Operand A, lanes_detail::Operand B>
  requires(lanes_detail::LaneExpr<A> || lanes_detail::LaneExpr<B>)
auto operator*(const A& a, const B& b) {
  return lanes_detail::make<lanes_detail::Mul>(a, b);
}
// Per lane std::max(a_i, b_i).
template <lanes_detail::Operand A, lanes_detail::Operand B>
  requires(lanes_detail::LaneExpr<A> || lanes_detail::LaneExpr<B>)
auto lane_max(const A& a, const B& b) {
  return lanes_detail::make<lanes_detail::Max>(a, b);
}
// Per lane f(a_i), for a function of one float (a phase function at each lane's g).
template <class F, lanes_detail::LaneExpr A>
auto lane_map(F f, const A& a) {
  return lanes_detail::Map<F, decltype(lanes_detail::hold(a))>{f, lanes_detail::hold(a)};
}
// Largest value of an expression over n lanes and 0 (as ConstLanes::max, without storing it).
template <lanes_detail::LaneExpr E>
float max_over(const E& e, int n) {
  return partial::max_from_zero(lanes_detail::hold(e), n);
}
// Σ over n lanes of an expression, in lane order.
template <lanes_detail::LaneExpr E>
float sum_over(const E& e, int n) {
  const auto x = lanes_detail::hold(e);
  float s = 0.0f;
  for (int i = 0; i < n; ++i) s += x[i];
  return s;
}

}  // namespace prizma::render
