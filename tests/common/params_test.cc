// the parameter declarations: bounds, the validator's paths and cross-field
// checks, against values chosen on and beside every edge
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "autonomy/common/params.h"

namespace paddock::params {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

enum class Mode { A, B };

struct Inner {
  double gain = 1.0;
  int count = 3;
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(gain), {"1/s", above(0.0), "a gain"});
    v(PADDOCK_PARAM(count), {"", in(1, 10), "a count"});
  }
  std::string check() const { return count > 5 && gain > 2.0 ? "count must be <= 5 when gain > 2" : ""; }
};

struct Outer {
  double share = 0.5;
  bool flag = true;
  Mode mode = Mode::A;
  std::optional<double> limit;
  std::vector<double> edges{1.0, 2.0};
  Inner inner;
  static constexpr Choice<Mode> kModes[] = {{"a", Mode::A}, {"b", Mode::B}};
  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(share), {"", fraction(), "a share"});
    v(PADDOCK_PARAM(flag), "a flag");
    v(PADDOCK_PARAM(mode), kModes, "a mode");
    v(PADDOCK_PARAM(limit), {"m", at_least(0.0), "an optional limit"});
    v(PADDOCK_PARAM(edges), {"m", above(0.0), "a list"});
    v.section(PADDOCK_PARAM(inner), "the inner part");
  }
};

TEST(Params, BoundsIncludeOrExcludeTheirEdgesAndRejectNonFinite) {
  EXPECT_TRUE(at_least(0.0).contains(0.0));
  EXPECT_FALSE(above(0.0).contains(0.0));
  EXPECT_TRUE(above(0.0).contains(1e-300));
  EXPECT_TRUE(at_most(1.0).contains(1.0));
  EXPECT_FALSE(below(1.0).contains(1.0));
  EXPECT_TRUE(in(0.0, 1.0).contains(0.0));
  EXPECT_TRUE(in(0.0, 1.0).contains(1.0));
  EXPECT_FALSE(in(0.0, 1.0).contains(1.0000001));
  EXPECT_FALSE(above_up_to(0.0, 1.0).contains(0.0));
  EXPECT_TRUE(above_up_to(0.0, 1.0).contains(1.0));
  EXPECT_FALSE(from_below(0.0, 1.0).contains(1.0));
  EXPECT_TRUE(any().contains(-1e300));
  for (const Bounds& b : {any(), at_least(0.0), in(0.0, 1.0)}) {
    EXPECT_FALSE(b.contains(kNaN));
    EXPECT_FALSE(b.contains(std::numeric_limits<double>::infinity()));
  }
}

TEST(Params, BoundsReadAsText) {
  EXPECT_EQ(bounds_text(above(0.0), "m"), "> 0 m");
  EXPECT_EQ(bounds_text(at_least(1), ""), ">= 1");
  EXPECT_EQ(bounds_text(in(0.0, 1.0), ""), "in [0, 1]");
  EXPECT_EQ(bounds_text(above_up_to(0.0, 1.5), "rad"), "in (0, 1.5] rad");
  EXPECT_EQ(bounds_text(below(2.0), "s"), "< 2 s");
  EXPECT_EQ(bounds_text(any(), "m"), "a finite number m");
  EXPECT_EQ(number(0.1), "0.1");
  EXPECT_EQ(number(1e-7), "1e-07");
}

TEST(Params, DefaultsAreValid) { EXPECT_EQ(validate(Outer{}), ""); }

TEST(Params, TheFirstBadFieldIsNamedByItsPath) {
  Outer o;
  o.inner.gain = 0.0;
  EXPECT_EQ(validate(o), "inner.gain must be > 0 1/s (got 0)");
  o.share = 1.5;  // earlier in declaration order: named first
  EXPECT_EQ(validate(o), "share must be in [0, 1] (got 1.5)");
  Outer n;
  n.inner.gain = kNaN;
  EXPECT_EQ(validate(n).rfind("inner.gain must be > 0", 0), 0u);
}

TEST(Params, IntegersAndOptionalsAreChecked) {
  Outer o;
  o.inner.count = 0;
  EXPECT_EQ(validate(o), "inner.count must be in [1, 10] (got 0)");
  Outer p;
  p.limit = -1.0;
  EXPECT_EQ(validate(p), "limit must be >= 0 m (got -1)");
  p.limit.reset();  // unset: nothing to check
  EXPECT_EQ(validate(p), "");
}

TEST(Params, EveryItemOfAListIsChecked) {
  Outer o;
  o.edges = {1.0, 0.0, -1.0};
  EXPECT_EQ(validate(o), "edges[1] must be > 0 m (got 0)");
  o.edges.clear();
  EXPECT_EQ(validate(o), "");
}

TEST(Params, CrossFieldChecksRunWithTheirPath) {
  Outer o;
  o.inner.gain = 3.0;
  o.inner.count = 6;
  EXPECT_EQ(validate(o), "inner.count must be <= 5 when gain > 2");
  EXPECT_EQ(validate(o.inner), "count must be <= 5 when gain > 2");
}

TEST(Params, AnEnumValueWithoutANameIsRejected) {
  Outer o;
  o.mode = static_cast<Mode>(7);
  EXPECT_EQ(validate(o), "mode has a value that is not one of its names");
}

TEST(Params, RequireValidThrowsWithTheStructsName) {
  Inner bad;
  bad.count = 11;
  EXPECT_THROW(require_valid(bad, "Inner"), std::invalid_argument);
  try {
    require_valid(bad, "Inner");
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "Inner: count must be in [1, 10] (got 11)");
  }
  EXPECT_NO_THROW(require_valid(Inner{}, "Inner"));
}

TEST(Params, AVisitorSeesEveryFieldOnceInDeclarationOrder) {
  EXPECT_EQ(field_paths(Outer{}), (std::vector<std::string>{"share", "flag", "mode", "limit", "edges", "inner.gain", "inner.count"}));
}

// the fingerprint is a cache key: the same values give the same text, a
// change of any one field (nested, in a list, an optional set or unset, the
// last bit of a double) gives another
TEST(Params, FingerprintsDifferInEveryFieldAndAgreeOnEqualValues) {
  const Outer base;
  EXPECT_EQ(fingerprint(base), fingerprint(Outer{}));
  EXPECT_EQ(fingerprint(base), "share=0.5\nflag=true\nmode=0\nlimit=unset\nedges=list of 2\nedges[0]=1\nedges[1]=2\n"
                               "inner.gain=1\ninner.count=3\n");
  std::vector<Outer> changed(9);
  changed[0].share = std::nextafter(0.5, 1.0);
  changed[1].flag = false;
  changed[2].mode = Mode::B;
  changed[3].limit = 0.0;
  changed[4].edges.push_back(3.0);
  changed[5].edges[1] = 2.5;
  changed[6].inner.gain = 1.5;
  changed[7].inner.count = 4;
  changed[8].edges = {1.0};
  for (std::size_t i = 0; i < changed.size(); ++i) {
    EXPECT_NE(fingerprint(changed[i]), fingerprint(base)) << i;
    for (std::size_t j = 0; j < i; ++j) EXPECT_NE(fingerprint(changed[i]), fingerprint(changed[j])) << i << " " << j;
  }
}

}  // namespace
}  // namespace paddock::params
