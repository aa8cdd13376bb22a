#pragma once
/// \file expr.h
/// The expressions of cpfg's language (module parameters, conditions, probabilities), compiled
/// once into a flat bytecode and evaluated on a fixed stack without allocation. Private to
/// growth/lsystem/.
///
/// Operators and precedence follow cpfg's grammar (lsys_input.y), lowest first: `?:` (right
/// associative), `||`, `&&`, `== !=`, `< <= > >=`, `+ -`, `* / %`, `^` (power, left
/// associative), unary `-` and `!`. So `-2^2` is 4 and `2^3^2` is 64, as in cpfg.
/// Trigonometric functions take and give degrees (cpfg). `ran(x)` is uniform in [0, x),
/// `nran(m, s)` normal with mean m and standard deviation s; both are keyed by the seed, the
/// step, the module's position and the call's number within the module, so a derivation is
/// the same for a seed whatever else is drawn.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace lobe::lsystem {
class Environment;
}

namespace lobe::lsystem::detail {

enum class Op : std::uint8_t {
    Const, Var,
    Neg, Not,
    Add, Sub, Mul, Div, Mod, Pow,
    Lt, Le, Gt, Ge, Eq, Ne,
    AndJump,     ///< pop a; a == 0: push 0 and jump by arg; else go on
    OrJump,      ///< pop a; a != 0: push 1 and jump by arg; else go on
    ToBool,      ///< top = (top != 0)
    JumpIfFalse, ///< pop a; a == 0: jump by arg
    Jump,        ///< jump by arg
    Sin, Cos, Tan, Asin, Acos, Atan, Atan2, Exp, Log, Sqrt, Floor, Ceil, Trunc, Fabs, Sign,
    Min, Max, PowFn,
    Ran, NRan, Inside,
    Stub, ///< pops argc values, pushes `value` (a cpfg function read but not supported)
};

/// One instruction. Jumps are relative (arg = offset from this instruction), so a block of
/// code can be moved (constant folding of `?:`).
struct Instr {
    Op op = Op::Const;
    std::uint8_t argc = 0;
    std::uint32_t arg = 0;
    double value = 0.0;
};

/// A compiled expression: a range of the system's code.
struct Expr {
    std::uint32_t first = 0;
    std::uint32_t count = 0;
    std::uint32_t max_stack = 0;
    bool constant = false; ///< a single Const: `value` is the result
    double value = 0.0;
    std::size_t offset = 0; ///< where it starts in the source text
};

/// Deepest expression nesting (parentheses, calls, unary chains, #define expansions).
inline constexpr int kMaxExprNesting = 100;
/// Deepest evaluation stack an expression may need.
inline constexpr std::uint32_t kMaxExprStack = 256;
/// Most instructions in one system (all expressions together).
inline constexpr std::size_t kMaxCodeSize = std::size_t{1} << 22;

/// What evaluation needs besides the code.
struct EvalContext {
    const double* vars = nullptr;
    std::uint64_t seed = 0;
    std::uint64_t step_key = 0;  ///< the step (and pass), mixed into the random keys
    std::uint64_t position = 0;  ///< the module's position in the word being rewritten
    std::uint32_t draws = 0;     ///< ran()/nran() calls so far for this module
    const Environment* environment = nullptr;
};

enum class EvalError : std::uint8_t { None, DivisionByZero, ModuloByZero };

/// Runs `e` (e.constant handled by the caller or here). Returns None and sets `out`, or the
/// error.
EvalError evaluate(const std::vector<Instr>& code, const Expr& e, EvalContext& ctx, double& out);

const char* eval_error_text(EvalError e);

/// The random draws of ran()/nran(), exposed for tests: uniform in [0, 1) for a key.
double keyed_uniform(std::uint64_t seed, std::uint64_t step_key, std::uint64_t position, std::uint32_t draw);

/// The source text being compiled and how to report errors and warnings in it.
class SourceText {
public:
    SourceText(std::string_view text, std::string name);
    std::string_view text() const { return text_; }
    const std::string& name() const { return name_; }
    /// 1-based line and column of a byte offset.
    std::pair<std::size_t, std::size_t> line_col(std::size_t offset) const;
    /// "NAME:LINE:COL: " for an offset.
    std::string where(std::size_t offset) const;
    [[noreturn]] void fail(std::size_t offset, const std::string& message) const;

private:
    std::string_view text_;
    std::string name_;
    std::vector<std::size_t> line_starts_;
};

/// A `#define NAME value`: the value's text, expanded where the name is used (as a
/// parenthesised sub-expression).
struct Define {
    std::size_t name_offset = 0;
    std::size_t begin = 0; ///< the value's text in the source
    std::size_t end = 0;
    bool expanding = false;
};

/// Compiles expressions of one source into one code vector.
class ExprCompiler {
public:
    ExprCompiler(const SourceText& source, std::vector<Instr>& code,
                 std::unordered_map<std::string, Define>& defines,
                 std::function<void(std::size_t, const std::string&)> warn);

    /// Formal parameter names of the production being compiled: name → variable slot.
    void set_scope(const std::unordered_map<std::string, std::uint32_t>* scope) { scope_ = scope; }

    /// Parses one expression starting at `pos` (leading blanks skipped) and stops before the
    /// first character that cannot continue it (`,` `)` or the end of the range); `pos` is
    /// moved there. \throw InvalidInput "NAME:LINE:COL: …" for a malformed expression, an
    /// undefined name, a recursive #define, a constant division by zero, nesting over
    /// kMaxExprNesting.
    Expr compile(std::size_t& pos, std::size_t end);
    /// As compile(), the whole range must be one expression.
    Expr compile_all(std::size_t begin, std::size_t end);

    /// Evaluates a constant expression (no formal parameters; ran() keyed by seed 0).
    double evaluate_constant(const Expr& e, std::size_t offset);

    /// Whether a #define's value is a valid expression (checked once for every define, so
    /// that an unused `#define K 1/0` or a recursion is still reported).
    void check_define(const std::string& name);

private:
    struct Cursor {
        std::size_t pos;
        std::size_t end;
    };
    enum class Tok : std::uint8_t { End, Number, Name, String, Op, LParen, RParen, Comma, Question, Colon };
    struct Token {
        Tok kind = Tok::End;
        std::size_t begin = 0;
        std::size_t end = 0;
        double number = 0.0;
        std::string_view text;
    };

    Token lex(Cursor& c) const;
    Token peek(const Cursor& c) const;
    Token next(Cursor& c);
    void expect(Cursor& c, Tok kind, const char* what);

    // Each parse function emits code leaving one value on the stack and returns where that
    // code starts (for constant folding).
    std::size_t parse_ternary(Cursor& c, int depth);
    std::size_t parse_binary(Cursor& c, int level, int depth);
    std::size_t parse_unary(Cursor& c, int depth);
    std::size_t parse_primary(Cursor& c, int depth);
    std::size_t parse_call(Cursor& c, const Token& name, int depth);
    std::size_t parse_name(const Token& name, int depth);

    void emit(Op op, std::uint32_t arg = 0, double value = 0.0, std::uint8_t argc = 0);
    void adjust_depth(int delta);
    bool is_constant_from(std::size_t start) const
    {
        return code_.size() == start + 1 && code_[start].op == Op::Const;
    }
    /// Replaces the code from `start` by one constant.
    void fold_to(std::size_t start, double value);

    const SourceText& src_;
    std::vector<Instr>& code_;
    std::unordered_map<std::string, Define>& defines_;
    std::function<void(std::size_t, const std::string&)> warn_;
    const std::unordered_map<std::string, std::uint32_t>* scope_ = nullptr;
    std::uint32_t depth_ = 0;
    std::uint32_t max_depth_ = 0;
    std::vector<std::string> warned_functions_;
    bool lenient_ = false;
    std::size_t tokens_ = 0;     ///< tokens read, bounded so #define expansions cannot blow up
    std::size_t max_tokens_ = 0;
    // The last token peeked (the precedence levels peek the same token in turn).
    mutable std::size_t cache_pos_ = static_cast<std::size_t>(-1);
    mutable std::size_t cache_end_ = 0;
    mutable Token cache_token_;
    mutable std::size_t cache_next_ = 0;
};

/// Most tokens the expressions of a source of `bytes` bytes may read, every #define expansion
/// counting: a million plus two per byte, so that expansions cannot blow up.
inline std::size_t max_expr_tokens(std::size_t bytes) { return (std::size_t{1} << 20) + 2 * bytes; }

} // namespace lobe::lsystem::detail
