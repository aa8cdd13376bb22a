// The L-system engine (growth/lsystem/lsystem.h): golden vectors from the seeds
// (../shared/SEED-NOTES.md), the cpfg language's features, and bad input refused in one line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "core/errors.h"
#include "growth/lsystem/lsystem.h"
#include "tests/support/expect_throw.h"

namespace lobe::lsystem {
namespace {

LSystem parse(const std::string& text, std::vector<std::string>* warnings = nullptr)
{
    return parse_lsystem(text, "test.l", warnings);
}

/// The words of steps 0..n, as text.
std::vector<std::string> words(const LSystem& sys, int n, std::uint64_t seed = 1)
{
    std::vector<std::string> out;
    for (int k = 0; k <= n; ++k) {
        DeriveOptions o;
        o.steps = k;
        o.seed = seed;
        out.push_back(to_string(sys, derive(sys, o)));
    }
    return out;
}

std::string derived(const LSystem& sys, int steps, std::uint64_t seed = 1)
{
    DeriveOptions o;
    o.steps = steps;
    o.seed = seed;
    return to_string(sys, derive(sys, o));
}

/// The message of the InvalidInput that `f` throws ("" when it throws none).
template <class F>
std::string refusal(F&& f)
{
    try {
        f();
    } catch (const InvalidInput& e) {
        return e.what();
    }
    return "";
}

std::string parse_refusal(const std::string& text) { return refusal([&] { parse(text); }); }

// ---------------------------------------------------------------------------------------------
// Golden vectors

TEST(LSystemGolden, D0LAlgaeGivesTheSeedsSequenceFromB)
{
    const LSystem sys = parse("Lsystem: algae\nAxiom: b\na --> ab\nb --> a\nendlsystem\n");
    const std::vector<std::string> expected = {"b", "a", "ab", "aba", "abaab", "abaababa"};
    EXPECT_EQ(words(sys, 5), expected);
}

// Seed 002's context-sensitive bracketed system (ABOP §1.8): the seed imagines an invisible
// `1` at both ends of the word and at the end of every branch. cpfg has no such module: a
// module at an end simply has no context there, so a production with that context does not
// apply. The invisible `1` is written as productions: the eight two-sided ones first, then
// for each module without a right neighbour (the word's end, or the end of its branch) a
// production with only a left context giving what `l<p>1` gives, then those with only a right
// context giving `1<p>r`, and last the context-free ones giving `1<p>1`. Context-sensitive
// productions are tried in file order before context-free ones, so each module meets exactly
// the production of its (possibly invisible) neighbours. A branch's first module sees the
// module before the branch as its left context; a right context skips whole branches.
TEST(LSystemGolden, Seed002ContextSensitiveBracketedSystemGivesItsElevenWordsExactly)
{
    const LSystem sys = parse(R"(Lsystem: seed002
ignore: +-F
Axiom: 1
0 < 0 > 0 --> 0
0 < 0 > 1 --> 1[1]
0 < 1 > 0 --> 1
0 < 1 > 1 --> 1
1 < 0 > 0 --> 0
1 < 0 > 1 --> 11
1 < 1 > 0 --> 1
1 < 1 > 1 --> 0
/* no right neighbour: as if it were the invisible 1 */
0 < 0 --> 1[1]
0 < 1 --> 1
1 < 0 --> 11
1 < 1 --> 0
/* no left neighbour */
0 > 0 --> 0
0 > 1 --> 11
1 > 0 --> 1
1 > 1 --> 0
/* neither */
0 --> 11
1 --> 0
/* the turtle's angles flip (the seed's * < - > * and * < + > *) */
* < - > * --> +
* < + > * --> -
endlsystem
)");
    const std::vector<std::string> expected = {"1",          "0",          "11",          "00",
                                               "01[1]",      "111[0]",     "000[11]",     "001[1][10]",
                                               "01[1]1[0][111]", "111[0]0[11][000]", "001[11]11[10][001[1]]"};
    EXPECT_EQ(words(sys, 10), expected);
}

TEST(LSystemGolden, Seed000T4ParametricConditionsCountUpThenBranch)
{
    const LSystem sys = parse(R"(Lsystem: T4
Axiom: AB(1)
B(x) : x < 3 --> B(x+1)
B(x) : x >= 3 --> AB(1)
endlsystem
)");
    const std::vector<std::string> expected = {"AB(1)", "AB(2)", "AB(3)", "AAB(1)", "AAB(2)", "AAB(3)", "AAAB(1)"};
    EXPECT_EQ(words(sys, 6), expected);
}

TEST(LSystemGolden, Seed000T5NeedsTheContextSensitiveProductionToWin)
{
    // The context-free B(y) --> B(y+1) comes first in the file; the context-sensitive one must
    // still be tried first.
    const LSystem sys = parse(R"(Lsystem: T5
Axiom: A(1)B(1)
B(y) --> B(y+1)
A(x) < B(y) : y >= 3 --> A(x*0.5)B(1)
endlsystem
)");
    const std::vector<std::string> expected = {"A(1)B(1)",          "A(1)B(2)",          "A(1)B(3)",
                                               "A(1)A(0.5)B(1)",    "A(1)A(0.5)B(2)",    "A(1)A(0.5)B(3)",
                                               "A(1)A(0.5)A(0.25)B(1)"};
    EXPECT_EQ(words(sys, 6), expected);
}


// ---------------------------------------------------------------------------------------------
// Stochastic productions

TEST(LSystemStochastic, WeightsAreHonouredWithin2PercentOver10000Derivations)
{
    // Seed 002's stochastic example (its Java version ignored the weights).
    const LSystem sys = parse(R"(Lsystem: stochastic
Axiom: F
F --> F[+F]F[-F]F : .33
F --> F[+F]F : .33
F --> F[-F]F : .34
endlsystem
)");
    std::map<std::string, int> counts;
    const int runs = 10000;
    for (int seed = 1; seed <= runs; ++seed) ++counts[derived(sys, 1, static_cast<std::uint64_t>(seed))];
    ASSERT_EQ(counts.size(), 3u);
    EXPECT_NEAR(counts["F[+F]F[-F]F"] / double(runs), 0.33, 0.02);
    EXPECT_NEAR(counts["F[+F]F"] / double(runs), 0.33, 0.02);
    EXPECT_NEAR(counts["F[-F]F"] / double(runs), 0.34, 0.02);
}

TEST(LSystemStochastic, WeightsThatDoNotAddUpToOneGiveOneWarningAndAreNormalised)
{
    std::vector<std::string> warnings;
    const LSystem sys = parse(R"(Lsystem: s
Axiom: A
A --> B : 1
A --> C : 3
endlsystem
)",
                              &warnings);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0].rfind("test.l:3:1: ", 0), 0u) << warnings[0];
    EXPECT_NE(warnings[0].find("add up to 4"), std::string::npos) << warnings[0];
    int c = 0;
    const int runs = 10000;
    for (int seed = 0; seed < runs; ++seed) c += derived(sys, 1, static_cast<std::uint64_t>(seed)) == "C";
    EXPECT_NEAR(c / double(runs), 0.75, 0.02);
}

TEST(LSystemStochastic, TheSameSeedGivesTheSameWordAndAnotherSeedAnotherOne)
{
    const LSystem sys = parse(R"(Lsystem: s
Axiom: F
F --> F[+F]F : 0.5
F --> F[-F]F : 0.5
endlsystem
)");
    EXPECT_EQ(derived(sys, 5, 7), derived(sys, 5, 7));
    EXPECT_NE(derived(sys, 5, 7), derived(sys, 5, 8));
}

// ---------------------------------------------------------------------------------------------
// Expressions

std::vector<double> axiom_params(const std::string& params)
{
    const LSystem sys = parse("Lsystem: e\nAxiom: X(" + params + ")\nendlsystem\n");
    return sys.axiom().params;
}

TEST(LSystemExpressions, OperatorsFollowCpfgsPrecedence)
{
    const std::vector<double> v = axiom_params("1+2*3, -2^2, 2^3^2, 7%3, !0, !5, 1&&0, 0||2, 3>2?10:20, "
                                               "1<2, 2<=2, 3>=4, 1==1, 1!=1, (1+2)*3, 10/4-1");
    const std::vector<double> expected = {7, 4, 64, 1, 1, 0, 0, 1, 10, 1, 1, 0, 1, 0, 9, 1.5};
    EXPECT_EQ(v, expected);
}

TEST(LSystemExpressions, TrigonometricFunctionsTakeAndGiveDegreesAsCpfg)
{
    const std::vector<double> v = axiom_params("sin(30), cos(60), tan(45), asin(1), acos(0), atan(1), atan2(1, -1)");
    const std::vector<double> expected = {0.5, 0.5, 1, 90, 90, 45, 135};
    ASSERT_EQ(v.size(), expected.size());
    for (std::size_t i = 0; i < v.size(); ++i) EXPECT_NEAR(v[i], expected[i], 1e-12) << i;
}

TEST(LSystemExpressions, TheOtherFunctionsAreTheCLibrarysOnes)
{
    const std::vector<double> v =
        axiom_params("exp(0), log(1), sqrt(16), floor(-1.5), ceil(-1.5), trunc(-1.5), fabs(-3), min(2, 3), "
                     "max(2, 3), sign(-4), sign(0), pow(2, 10)");
    const std::vector<double> expected = {1, 0, 4, -2, -1, -1, 3, 2, 3, -1, 0, 1024};
    EXPECT_EQ(v, expected);
}

TEST(LSystemExpressions, ParametersConditionsAndDefinesWorkTogether)
{
    const LSystem sys = parse(R"(Lsystem: p
#define R 0.5
#define ANGLE (R * 60)
derivation length: 2
Axiom: A(8, 1)
A(l, w) : l > 1 && w > 0 --> F(l)[+(ANGLE)A(l*R, w)]A(l*R, w)
endlsystem
)");
    EXPECT_EQ(derive(sys).size(), 16u);
    EXPECT_EQ(derived(sys, 1), "F(8)[+(30)A(4,1)]A(4,1)");
}

TEST(LSystemExpressions, RanAndNranAreKeyedBySeedStepAndPosition)
{
    const LSystem sys = parse(R"(Lsystem: r
Axiom: A
A --> B(ran(10))C(nran(5, 2))
endlsystem
)");
    Word w;
    const auto a = static_cast<SymbolId>(sys.find_symbol("A"));
    for (int i = 0; i < 20000; ++i) w.push(a);
    DeriveOptions o;
    o.seed = 3;
    Word out1, out2, out3;
    derive_step(sys, w, out1, 1, o);
    derive_step(sys, w, out2, 1, o);
    EXPECT_EQ(out1.params, out2.params) << "the same seed and step give the same numbers";
    o.seed = 4;
    derive_step(sys, w, out3, 1, o);
    EXPECT_NE(out1.params, out3.params) << "another seed gives others";
    double sum_b = 0.0, sum_c = 0.0, sum_c2 = 0.0;
    bool in_range = true;
    for (std::size_t i = 0; i < out1.params.size(); i += 2) {
        const double b = out1.params[i], c = out1.params[i + 1];
        in_range = in_range && b >= 0.0 && b < 10.0;
        sum_b += b;
        sum_c += c;
        sum_c2 += c * c;
    }
    const double n = 20000.0;
    EXPECT_TRUE(in_range) << "ran(10) is in [0, 10)";
    EXPECT_NEAR(sum_b / n, 5.0, 0.1);
    const double mean_c = sum_c / n;
    EXPECT_NEAR(mean_c, 5.0, 0.05);
    EXPECT_NEAR(std::sqrt(sum_c2 / n - mean_c * mean_c), 2.0, 0.05);
}

struct RightHalf : Environment {
    bool inside(const glm::dvec3& p) const override { return p.x > 0.0; }
};

TEST(LSystemExpressions, InsideAsksTheEnvironmentAndIsOneWithoutOne)
{
    const LSystem sys = parse(R"(Lsystem: env
Axiom: P(-1)P(2)
P(x) : inside(x, 0, 0) --> I
P(x) --> O
endlsystem
)");
    RightHalf env;
    DeriveOptions o;
    o.steps = 1;
    o.environment = &env;
    EXPECT_EQ(to_string(sys, derive(sys, o)), "OI");
    EXPECT_EQ(derived(sys, 1), "II");
}

// ---------------------------------------------------------------------------------------------
// Context

TEST(LSystemContext, IgnoredModulesAreSkippedWhenMatchingContext)
{
    const LSystem sys = parse(R"(Lsystem: c
ignore: +-F
Axiom: A+F-B
A < B --> X
endlsystem
)");
    EXPECT_EQ(derived(sys, 1), "A+F-X");
}

TEST(LSystemContext, ConsiderListsTheOnlyModulesThatCount)
{
    const LSystem sys = parse(R"(Lsystem: c
consider: AB
Axiom: AQRB
A < B --> X
endlsystem
)");
    EXPECT_EQ(derived(sys, 1), "AQRX");
    const LSystem without = parse("Lsystem: c\nAxiom: AQRB\nA < B --> X\nendlsystem\n");
    EXPECT_EQ(derived(without, 1), "AQRB");
}

TEST(LSystemContext, ABranchsFirstModuleSeesTheModuleBeforeTheBranch)
{
    const LSystem sys = parse("Lsystem: c\nAxiom: A[B][B]CB\nA < B --> X\nendlsystem\n");
    // Both branches start after A; the last B's left context is C.
    EXPECT_EQ(derived(sys, 1), "A[X][X]CB");
}

TEST(LSystemContext, ARightContextSkipsWholeBranchesAndEndsWithItsBranch)
{
    const LSystem sys = parse("Lsystem: c\nAxiom: A[B]C[AE]\nA > C --> X\nendlsystem\n");
    // The first A sees C past the branch; the second A's right is E, not C.
    EXPECT_EQ(derived(sys, 1), "X[B]C[AE]");
}

TEST(LSystemContext, ARightContextMayNameABranchAsCpfgAllows)
{
    const LSystem sys = parse("Lsystem: c\nAxiom: A[B]C A[D]C\nA > [B]C --> X\nendlsystem\n");
    EXPECT_EQ(derived(sys, 1), "X[B]CA[D]C");
}

TEST(LSystemContext, ContextOverManySiblingBranchesAndIgnoredRunsIsLinear)
{
    // Each B's left context walks back over every earlier sibling branch, and each A's right
    // context over every A after it: quadratic (minutes) if walked module by module.
    const LSystem sys = parse("Lsystem: c\nignore: A\nAxiom: A[B]C\nA < B --> X\nA > C --> Y\nendlsystem\n");
    const auto a = static_cast<SymbolId>(sys.find_symbol("A"));
    const auto b = static_cast<SymbolId>(sys.find_symbol("B"));
    const auto c = static_cast<SymbolId>(sys.find_symbol("C"));
    const auto open = static_cast<SymbolId>(sys.find_symbol("["));
    const auto close = static_cast<SymbolId>(sys.find_symbol("]"));
    Word w;
    const int n = 300000;
    for (int k = 0; k < n; ++k) w.push(a);
    for (int k = 0; k < n; ++k) {
        w.push(open);
        w.push(b);
        w.push(close);
    }
    w.push(c);
    Word out;
    derive_step(sys, w, out, 1, {});
    const auto x = static_cast<SymbolId>(sys.find_symbol("X"));
    const auto y = static_cast<SymbolId>(sys.find_symbol("Y"));
    std::size_t xs = 0, ys = 0;
    for (const Module& m : out.modules) {
        xs += m.symbol == x;
        ys += m.symbol == y;
    }
    // A is ignored, so the B's see nothing before the branches; every A sees C past them.
    EXPECT_EQ(xs, 0u);
    EXPECT_EQ(ys, static_cast<std::size_t>(n));
    const LSystem plain = parse("Lsystem: c\nAxiom: A[B]C\nA < B --> X\nendlsystem\n");
    Word w2;
    w2.push(static_cast<SymbolId>(plain.find_symbol("A")));
    for (int k = 0; k < n; ++k) {
        w2.push(static_cast<SymbolId>(plain.find_symbol("[")));
        w2.push(static_cast<SymbolId>(plain.find_symbol("B")));
        w2.push(static_cast<SymbolId>(plain.find_symbol("]")));
    }
    derive_step(plain, w2, out, 1, {});
    const auto x2 = static_cast<SymbolId>(plain.find_symbol("X"));
    xs = 0;
    for (const Module& m : out.modules) xs += m.symbol == x2;
    EXPECT_EQ(xs, static_cast<std::size_t>(n));
}

TEST(LSystemContext, ContextParametersAreBoundToTheMatchedModules)
{
    const LSystem sys = parse(R"(Lsystem: c
Axiom: A(1)B(2)C(3)
A(a) < B(b) > C(c) --> B(a + b * 10 + c * 100)
endlsystem
)");
    EXPECT_EQ(derived(sys, 1), "A(1)B(321)C(3)");
}

TEST(LSystemContext, ParameterCountsMustMatchAsInCpfg)
{
    const LSystem sys = parse("Lsystem: c\nAxiom: A A(1) A(1,2)\nA(x) --> B(x)\nendlsystem\n");
    EXPECT_EQ(derived(sys, 1), "AB(1)A(1,2)");
}

// ---------------------------------------------------------------------------------------------
// Decomposition, homomorphism, cut, queries

TEST(LSystemSections, DecompositionIsAppliedAfterEachStepUpToItsMaximumDepth)
{
    auto system = [](int depth) {
        return parse("Lsystem: d\nAxiom: S\nS --> SA\ndecomposition\nmaximum depth: " + std::to_string(depth) +
                     "\nA --> B\nB --> C\nC --> D\nendlsystem\n");
    };
    EXPECT_EQ(derived(system(1), 1), "SB");
    EXPECT_EQ(derived(system(2), 1), "SC");
    EXPECT_EQ(derived(system(3), 1), "SD");
    EXPECT_EQ(derived(system(50), 1), "SD") << "a deeper limit stops where no production applies";
    // After every step the whole word is decomposed again: the B of step 1 becomes C.
    EXPECT_EQ(derived(system(1), 2), "SBC");
    EXPECT_EQ(derived(system(2), 2), "SCD");
    const LSystem defaults = parse("Lsystem: d\nAxiom: S\nS --> SA\ndecomposition\nA --> B\nB --> C\nendlsystem\n");
    EXPECT_EQ(derived(defaults, 1), "SB") << "cpfg's default maximum depth is 1";
}

TEST(LSystemSections, HomomorphismChangesOnlyTheInterpretationWordUpToItsDepth)
{
    const LSystem sys = parse(R"(Lsystem: h
Axiom: A
A --> AB
homomorphism
maximum depth: 2
B --> [+F]
F --> FF
endlsystem
)");
    const Word w = derive(sys, [] { DeriveOptions o; o.steps = 2; return o; }());
    EXPECT_EQ(to_string(sys, w), "ABB");
    EXPECT_EQ(to_string(sys, interpretation_word(sys, w)), "A[+FF][+FF]");
    const LSystem none = parse("Lsystem: h\nAxiom: AB\nendlsystem\n");
    EXPECT_EQ(to_string(none, interpretation_word(none, none.axiom())), "AB");
}

TEST(LSystemSections, TheCutSymbolRemovesTheRestOfItsBranch)
{
    const LSystem sys = parse("Lsystem: cut\nAxiom: F[A%B[C]D]E[%G]H%IJ\nendlsystem\n");
    EXPECT_EQ(derived(sys, 1), "F[A]E[]H");
    EXPECT_EQ(derived(sys, 0), "F[A%B[C]D]E[%G]H%IJ") << "the axiom itself is not cut";
}

TEST(LSystemSections, QueriesAreAnsweredBeforeTheFirstStepAndAfterEachStep)
{
    const LSystem sys = parse(R"(Lsystem: q
Axiom: ?P(0,0,0)A
?P(x,y,z) < A : y > 2 --> B
endlsystem
)");
    ASSERT_TRUE(sys.has_queries());
    int calls = 0;
    DeriveOptions o;
    o.steps = 5;
    o.answer_queries = [&](Word& w) {
        for (const Module& m : w.modules)
            if (sys.symbol_name(m.symbol) == "?P") w.params_of(m)[1] = calls;
        ++calls;
    };
    const Word w = derive(sys, o);
    EXPECT_EQ(calls, 6);
    // The query holds y = 3 after the third step, so the fourth rewrites A.
    EXPECT_EQ(to_string(sys, w), "?P(0,5,0)B");
    EXPECT_FALSE(parse("Lsystem: q\nAxiom: A\nendlsystem\n").has_queries());
}

// ---------------------------------------------------------------------------------------------
// The cpfg language

TEST(LSystemLanguage, ReadsCommentsArrowsEmptySuccessorsAndLongSymbols)
{
    std::vector<std::string> warnings;
    const LSystem sys = parse(R"(/* a comment before */
Lsystem: lang // a comment after
// a whole-line comment
derivation length: 1
Axiom: A B /* inside */ C @o ?E(1) F(1)
A -> /////F
B --> *
C : * --> D
endlsystem
)",
                              &warnings);
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    EXPECT_EQ(to_string(sys, derive(sys)), "/////FD@o?E(1)F(1)");
    EXPECT_GE(sys.find_symbol("@o"), 0);
    EXPECT_GE(sys.find_symbol("?E"), 0);
    EXPECT_EQ(sys.find_symbol("Q"), -1);
}

TEST(LSystemLanguage, UnsupportedFeaturesGiveOneWarningEachAndAStandIn)
{
    std::vector<std::string> warnings;
    const LSystem sys = parse(R"(#include "things.h"
Lsystem: warn
seed: 4
define: { array a[3]; }
start: {
  x = 1;
}
Axiom: A(func(1, 0.5))
A(x) : { y = 2; } x > 0 --> B
endlsystem
)",
                              &warnings);
    ASSERT_EQ(warnings.size(), 6u);
    EXPECT_EQ(warnings[0].rfind("test.l:1:1: ", 0), 0u) << warnings[0];
    EXPECT_EQ(warnings[1].rfind("test.l:3:1: ", 0), 0u) << warnings[1];
    EXPECT_EQ(warnings[2].rfind("test.l:4:9: ", 0), 0u) << warnings[2];
    EXPECT_EQ(warnings[3].rfind("test.l:5:8: ", 0), 0u) << warnings[3];
    EXPECT_EQ(warnings[4].rfind("test.l:8:10: ", 0), 0u) << warnings[4];
    EXPECT_EQ(warnings[5].rfind("test.l:9:8: ", 0), 0u) << warnings[5];
    EXPECT_EQ(to_string(sys, sys.axiom()), "A(1)");
    EXPECT_EQ(derived(sys, 1), "B");
}

TEST(LSystemLanguage, NumbersAreWrittenInTheirShortestExactForm)
{
    const LSystem sys = parse("Lsystem: n\nAxiom: F(1.5)[+(30)A(0.1, -2.5e-7, 1e21)]B\nendlsystem\n");
    EXPECT_EQ(to_string(sys, sys.axiom()), "F(1.5)[+(30)A(0.1,-2.5e-07,1e+21)]B");
}

// ---------------------------------------------------------------------------------------------
// View files

TEST(LSystemView, ReadsTheTurtlesLinesAndSkipsTheOthersWithAWarning)
{
    std::vector<std::string> warnings;
    const ViewSettings v = parse_view(R"(angle factor: 16
initial line width: 3 pixels
line width increment: 0.5
scale factor: 0.9
viewpoint: 0,0,1
tropism direction: 0, -2, 0
initial elasticity: 0.25
elasticity increment: 0.05
)",
                                      "test.v", &warnings);
    EXPECT_DOUBLE_EQ(v.angle_increment_deg, 22.5);
    EXPECT_DOUBLE_EQ(v.initial_line_width, 3.0);
    EXPECT_DOUBLE_EQ(v.line_width_increment, 0.5);
    EXPECT_DOUBLE_EQ(v.scale_factor, 0.9);
    EXPECT_EQ(v.tropism_direction, glm::dvec3(0, -1, 0));
    EXPECT_DOUBLE_EQ(v.elasticity, 0.25);
    EXPECT_DOUBLE_EQ(v.elasticity_increment, 0.05);
    EXPECT_TRUE(v.tropism);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_EQ(warnings[0].rfind("test.v:5:1: ", 0), 0u) << warnings[0];
    const ViewSettings t = parse_view("Angle Increment: 30\ntropism: T: 1,0,0, A: 0, E: 0.4\n", "t.v");
    EXPECT_DOUBLE_EQ(t.angle_increment_deg, 30.0);
    EXPECT_EQ(t.tropism_direction, glm::dvec3(1, 0, 0));
    EXPECT_DOUBLE_EQ(t.elasticity, 0.4);
}

TEST(LSystemView, WidthsArePixelsUnlessTheViewSaysPolygonsOrACylinderLineStyle)
{
    using Unit = ViewSettings::WidthUnit;
    EXPECT_EQ(ViewSettings{}.width_unit, Unit::Pixels); // cpfg's default
    EXPECT_EQ(parse_view("initial line width: 3\n", "a.v").width_unit, Unit::Pixels);
    EXPECT_EQ(parse_view("initial line width: 3 pixels\n", "a.v").width_unit, Unit::Pixels);
    EXPECT_EQ(parse_view("initial line width: 0.2 polygons\n", "a.v").width_unit, Unit::Model);
    EXPECT_EQ(parse_view("line style: cylinder\n", "a.v").width_unit, Unit::Model);
    EXPECT_EQ(parse_view("line style: polygon\n", "a.v").width_unit, Unit::Model);
    EXPECT_EQ(parse_view("line style: polygon\nline style: pixel\n", "a.v").width_unit, Unit::Pixels);
    EXPECT_DOUBLE_EQ(parse_view("initial line width: 0.2 polygons\n", "a.v").initial_line_width, 0.2);
    const std::string style = test::invalid_input_message([] { parse_view("line style: dotted\n", "b.v"); });
    EXPECT_EQ(style.rfind("b.v:1:12: ", 0), 0u) << style;
    const std::string unit = test::invalid_input_message([] { parse_view("initial line width: 2 inches\n", "c.v"); });
    EXPECT_EQ(unit.rfind("c.v:1:", 0), 0u) << unit;
}

TEST(LSystemView, LoadReadsTheViewFileBesideTheLFile)
{
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "lsystem_test_load";
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "plant.l") << "Lsystem: plant\nAxiom: F\nF --> FF\nendlsystem\n";
    std::ofstream(dir / "plant.v") << "angle increment: 25.7\nbackground colour: 0\n";
    const LSystemFile f = load_lsystem_file(dir / "plant.l");
    EXPECT_TRUE(f.has_view);
    EXPECT_DOUBLE_EQ(f.view.angle_increment_deg, 25.7);
    ASSERT_EQ(f.warnings.size(), 1u);
    EXPECT_NE(f.warnings[0].find("plant.v:2:1: "), std::string::npos) << f.warnings[0];
    std::ofstream(dir / "alone.l") << "Lsystem: alone\nAxiom: F\nendlsystem\n";
    EXPECT_FALSE(load_lsystem_file(dir / "alone.l").has_view);
    EXPECT_THROW(load_lsystem_file(dir / "missing.l"), FileError);
    std::filesystem::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// Bad input: one line naming the file, line and column

void expect_refused_at(const std::string& text, const std::string& where, const std::string& words_in_message)
{
    const std::string msg = parse_refusal(text);
    EXPECT_EQ(msg.rfind("test.l:" + where + ": ", 0), 0u) << "message: " << msg;
    EXPECT_NE(msg.find(words_in_message), std::string::npos) << "message: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

TEST(LSystemBadInput, UnbalancedBracketsAreRefusedWhereTheyAre)
{
    expect_refused_at("Lsystem: b\nAxiom: F\nF --> FF+[^F&F&F]-[&F^F^F\nendlsystem\n", "3:7", "unbalanced brackets");
    expect_refused_at("Lsystem: b\nAxiom: F]F\nendlsystem\n", "2:8", "unbalanced brackets");
}

TEST(LSystemBadInput, UnknownAndMalformedProductionsAreRefused)
{
    expect_refused_at("Lsystem: b\nAxiom: F\nF FF\nendlsystem\n", "3:1", "not a production");
    expect_refused_at("Lsystem: b\nAxiom: F\nF(x --> F\nendlsystem\n", "3:2", "unclosed '('");
    expect_refused_at("Lsystem: b\nAxiom: F\nF(1) --> F\nendlsystem\n", "3:3", "parameter name");
    expect_refused_at("Lsystem: b\nAxiom: F\nAB --> F\nendlsystem\n", "3:2", "one module");
    expect_refused_at("Lsystem: b\nAxiom: F\nF --> F(1,)\nendlsystem\n", "3:11", "expected a value");
    expect_refused_at("Lsystem: b\nAxiom: F\n --> F\nendlsystem\n", "3:2", "needs a predecessor");
    expect_refused_at("Lsystem: b\nAxiom: F\nF(x, x) --> F\nendlsystem\n", "3:6", "named twice");
    expect_refused_at("Lsystem: b\nAxiom: F\nF --> G(unknownfn(1))\nendlsystem\n", "3:9", "unknown function");
    expect_refused_at("Lsystem: b\nAxiom: F\nF --> G(sin(1, 2))\nendlsystem\n", "3:9", "takes 1 argument");
    expect_refused_at("Axiom: F\n", "1:1", "Lsystem:");
    expect_refused_at("Lsystem: b\nF --> G\nendlsystem\n", "3:1", "no 'Axiom:'");
}

TEST(LSystemBadInput, UndefinedConstantsAndRecursiveDefinesAreRefused)
{
    expect_refused_at("Lsystem: b\nAxiom: F(SIZE)\nendlsystem\n", "2:10", "undefined name 'SIZE'");
    expect_refused_at("Lsystem: b\nAxiom: F\nF(x) --> F(x * y)\nendlsystem\n", "3:16", "undefined name 'y'");
    expect_refused_at("#define A (B + 1)\n#define B (A * 2)\nLsystem: b\nAxiom: F\nendlsystem\n", "1:9",
                      "recursive #define 'A'");
    expect_refused_at("#define LOOP LOOP\nLsystem: b\nAxiom: F(LOOP)\nendlsystem\n", "1:9", "recursive");
}

TEST(LSystemBadInput, ConstantDivisionByZeroIsRefusedWhenRead)
{
    expect_refused_at("#define K (1 / 0)\nLsystem: b\nAxiom: F\nendlsystem\n", "1:14", "division by zero");
    expect_refused_at("Lsystem: b\nAxiom: F\nF --> F(2 % (1 - 1))\nendlsystem\n", "3:11", "division by zero");
}

TEST(LSystemBadInput, DivisionByZeroWhileDerivingNamesTheStepAndTheModule)
{
    const LSystem sys = parse("Lsystem: b\nAxiom: A(2)\nA(x) --> A(x - 1)B(1 / x)\nendlsystem\n");
    const std::string msg = refusal([&] { derived(sys, 5); });
    EXPECT_EQ(msg.rfind("test.l: step 3: division by zero", 0), 0u) << msg;
    EXPECT_NE(msg.find("A(0)"), std::string::npos) << msg;
    EXPECT_NE(msg.find("test.l:3:1"), std::string::npos) << msg;
}

TEST(LSystemBadInput, AWordPastTheLimitsStopsWithTheStepAndNoAllocation)
{
    const LSystem sys = parse("Lsystem: b\nAxiom: F\nF --> FF\nendlsystem\n");
    DeriveOptions o;
    o.steps = 40; // 2^40 modules if nothing stopped it
    o.max_modules = 1000;
    const std::string msg = refusal([&] { derive(sys, o); });
    EXPECT_EQ(msg, "test.l: step 10: the word would grow to 1024 modules, over the limit of 1000");
    const LSystem params = parse("Lsystem: b\nAxiom: F(1)\nF(x) --> F(x)F(x)\nendlsystem\n");
    o.max_modules = kMaxModules;
    o.max_param_values = 100;
    EXPECT_NE(refusal([&] { derive(params, o); }).find("step 7: the word would hold 128 parameter values"),
              std::string::npos);
}

TEST(LSystemBadInput, DerivationLengthsPastTheLimitAreRefused)
{
    expect_refused_at("Lsystem: b\nderivation length: 100001\nAxiom: F\nendlsystem\n", "2:20", "derivation length");
    const LSystem sys = parse("Lsystem: b\nAxiom: F\nendlsystem\n");
    DeriveOptions o;
    o.steps = kMaxDerivationLength + 1;
    EXPECT_NE(refusal([&] { derive(sys, o); }).find("over the limit of 100000"), std::string::npos);
}

TEST(LSystemBadInput, DeepNestingIsRefusedWithoutExhaustingTheStack)
{
    const std::string deep = "Lsystem: b\nAxiom: F(" + std::string(100000, '(') + "1" + std::string(100000, ')') +
                             ")\nendlsystem\n";
    const std::string msg = parse_refusal(deep);
    EXPECT_EQ(msg.rfind("test.l:2:", 0), 0u) << msg;
    EXPECT_NE(msg.find("nested too deeply"), std::string::npos) << msg;
    const std::string unary = "Lsystem: b\nAxiom: F(" + std::string(100000, '-') + "1)\nendlsystem\n";
    EXPECT_NE(parse_refusal(unary).find("nested too deeply"), std::string::npos);
}

TEST(LSystemBadInput, DefinesThatExplodeWhenExpandedAreRefused)
{
    std::string text = "#define D0 (x + x)\n";
    for (int i = 1; i < 60; ++i)
        text += "#define D" + std::to_string(i) + " (D" + std::to_string(i - 1) + " + D" + std::to_string(i - 1) + ")\n";
    text += "Lsystem: b\nAxiom: F(1)\nF(x) --> F(D59)\nendlsystem\n";
    const std::string msg = parse_refusal(text);
    EXPECT_NE(msg.find("too large"), std::string::npos) << msg;
}

TEST(LSystemBadInput, FilesOverTheSizeLimitAreRefused)
{
    const std::string big(kMaxFileBytes + 1, ' ');
    EXPECT_EQ(parse_refusal(big), "test.l:1:1: the file is 8388609 bytes, over the limit of 8388608 bytes");
}

TEST(LSystemBadInput, MalformedViewValuesAreRefusedWithTheirLine)
{
    const std::string msg = refusal([] { parse_view("angle increment: 30\nscale factor: big\n", "test.v"); });
    EXPECT_EQ(msg.rfind("test.v:2:14: ", 0), 0u) << msg;
    EXPECT_NE(refusal([] { parse_view("tropism direction: 0,0,0\n", "test.v"); }).find("must not be zero"),
              std::string::npos);
}

TEST(LSystemBadInput, AWordOfAnotherSystemIsRefusedByDeriveStep)
{
    const LSystem sys = parse("Lsystem: b\nAxiom: F\nendlsystem\n");
    Word w;
    w.push(7);
    Word out;
    EXPECT_NE(refusal([&] { derive_step(sys, w, out, 1, {}); }).find("not one of this system's"), std::string::npos);
}

TEST(LSystemBadInput, WorkPastTheOperationBudgetStopsWithTheStep)
{
    std::string expr = "x";
    for (int i = 0; i < 200; ++i) expr += " + x * 0.5";
    const LSystem sys = parse("Lsystem: b\nAxiom: A(1)\nA(x) --> A(" + expr + ")A(x)\nendlsystem\n");
    DeriveOptions o;
    o.steps = 30;
    o.max_operations = 100000;
    const std::string msg = refusal([&] { derive(sys, o); });
    EXPECT_EQ(msg.rfind("test.l: step ", 0), 0u) << msg;
    EXPECT_NE(msg.find("went past 100000 operations"), std::string::npos) << msg;
}

TEST(LSystemBadInput, TheHomomorphismKeepsTheLimitsItIsGiven)
{
    const LSystem sys = parse("Lsystem: h\nAxiom: A\nhomomorphism\nmaximum depth: 30\nA --> AA\nendlsystem\n");
    DeriveOptions o;
    o.max_modules = 1000;
    const std::string msg = refusal([&] { interpretation_word(sys, sys.axiom(), o); });
    EXPECT_EQ(msg, "test.l: step 0: the word would grow to 1024 modules, over the limit of 1000");
}

} // namespace
} // namespace lobe::lsystem
