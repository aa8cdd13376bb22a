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

} // namespace
} // namespace lobe::lsystem
