// Operation counting for a generated C module: the module is compiled as C++ with its real
// type replaced by Counted<T>, which counts every floating-point operation it performs.
#ifndef SD_COUNT_HPP
#define SD_COUNT_HPP
#include <cmath>

namespace sd_count {
enum Op { ADD, MUL, DIV, SQRT, TRIG, EXP, CMP, NOPS };
extern unsigned long long n[NOPS];
}

template <class T> struct Counted {
    T v;
    Counted() = default;
    Counted(double x) : v(static_cast<T>(x)) {}
    template <class U> Counted(const Counted<U> &o) : v(static_cast<T>(o.v)) {}
    Counted &operator+=(Counted o) { ++sd_count::n[sd_count::ADD]; v += o.v; return *this; }
    Counted &operator-=(Counted o) { ++sd_count::n[sd_count::ADD]; v -= o.v; return *this; }
    Counted &operator*=(Counted o) { ++sd_count::n[sd_count::MUL]; v *= o.v; return *this; }
    Counted &operator/=(Counted o) { ++sd_count::n[sd_count::DIV]; v /= o.v; return *this; }
    Counted operator-() const { Counted r; r.v = -v; return r; }
    explicit operator double() const { return static_cast<double>(v); }
    explicit operator float() const { return static_cast<float>(v); }
};

#define SD_BIN(OP, K)                                                                    \
    template <class T> Counted<T> operator OP(Counted<T> a, Counted<T> b)               \
    { ++sd_count::n[sd_count::K]; Counted<T> r; r.v = a.v OP b.v; return r; }            \
    template <class T> Counted<T> operator OP(double a, Counted<T> b)                   \
    { return Counted<T>(a) OP b; }                                                        \
    template <class T> Counted<T> operator OP(Counted<T> a, double b)                   \
    { return a OP Counted<T>(b); }
SD_BIN(+, ADD)
SD_BIN(-, ADD)
SD_BIN(*, MUL)
SD_BIN(/, DIV)
#undef SD_BIN
#define SD_CMP(OP)                                                                       \
    template <class T> bool operator OP(Counted<T> a, Counted<T> b)                     \
    { ++sd_count::n[sd_count::CMP]; return a.v OP b.v; }                                  \
    template <class T> bool operator OP(double a, Counted<T> b) { return Counted<T>(a) OP b; } \
    template <class T> bool operator OP(Counted<T> a, double b) { return a OP Counted<T>(b); }
SD_CMP(<)
SD_CMP(>)
SD_CMP(<=)
SD_CMP(>=)
SD_CMP(==)
SD_CMP(!=)
#undef SD_CMP
#define SD_FN1(F, K)                                                                     \
    template <class T> Counted<T> F(Counted<T> a)                                         \
    { ++sd_count::n[sd_count::K]; Counted<T> r; r.v = std::F(a.v); return r; }
SD_FN1(sqrt, SQRT)
SD_FN1(sin, TRIG)
SD_FN1(cos, TRIG)
SD_FN1(asin, TRIG)
SD_FN1(atan, TRIG)
SD_FN1(exp, EXP)
SD_FN1(fabs, CMP)
#undef SD_FN1
template <class T> Counted<T> atan2(Counted<T> a, Counted<T> b)
{ ++sd_count::n[sd_count::TRIG]; Counted<T> r; r.v = std::atan2(a.v, b.v); return r; }
template <class T> Counted<T> pow(Counted<T> a, Counted<T> b)
{ ++sd_count::n[sd_count::EXP]; Counted<T> r; r.v = std::pow(a.v, b.v); return r; }
template <class T> bool isfinite(Counted<T> a) { return std::isfinite(a.v); }
#endif
