#include "growth/lsystem/expr.h"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <glm/vec3.hpp>

#include "core/errors.h"
#include "core/random.h"
#include "growth/lsystem/lsystem.h"

namespace lobe::lsystem::detail {

namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

bool is_name_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
bool is_name_char(char c) { return is_name_start(c) || (c >= '0' && c <= '9'); }
bool is_digit(char c) { return c >= '0' && c <= '9'; }

std::uint64_t mix(std::uint64_t a, std::uint64_t b) { return splitmix64(a ^ splitmix64(b)); }

double sign_of(double x) { return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0); }

struct FunctionInfo {
    const char* name;
    Op op;
    int arity;
    bool pure;
};

constexpr FunctionInfo kFunctions[] = {
    {"sin", Op::Sin, 1, true},     {"cos", Op::Cos, 1, true},     {"tan", Op::Tan, 1, true},
    {"asin", Op::Asin, 1, true},   {"acos", Op::Acos, 1, true},   {"atan", Op::Atan, 1, true},
    {"atan2", Op::Atan2, 2, true}, {"exp", Op::Exp, 1, true},     {"log", Op::Log, 1, true},
    {"sqrt", Op::Sqrt, 1, true},   {"floor", Op::Floor, 1, true}, {"ceil", Op::Ceil, 1, true},
    {"trunc", Op::Trunc, 1, true}, {"fabs", Op::Fabs, 1, true},   {"sign", Op::Sign, 1, true},
    {"min", Op::Min, 2, true},     {"max", Op::Max, 2, true},     {"pow", Op::PowFn, 2, true},
    {"ran", Op::Ran, 1, false},    {"nran", Op::NRan, 2, false},  {"inside", Op::Inside, 3, false},
};

/// cpfg functions read but not supported: a warning and a stand-in value.
struct StubInfo {
    const char* name;
    double value;
};
constexpr StubInfo kStubs[] = {
    {"func", 1.0},     {"srand", 0.0},   {"bran", 0.5},    {"biran", 0.0},   {"printf", 0.0},
    {"fprintf", 0.0},  {"fopen", 0.0},   {"fclose", 0.0},  {"fflush", 0.0},  {"fscanf", 0.0},
    {"stop", 0.0},     {"play", 0.0},    {"inblob", 0.0},  {"curveX", 0.0},  {"curveY", 0.0},
    {"curveZ", 0.0},   {"curveGAL", 0.0}, {"Display", 0.0}, {"vvXmin", 0.0}, {"vvXmax", 0.0},
    {"vvYmin", 0.0},   {"vvYmax", 0.0},  {"vvZmin", 0.0},  {"vvZmax", 0.0},  {"vvScale", 0.0},
    {"SetDerivationLength", 0.0}, {"GetDerivationLength", 0.0},
};

/// One pure operation on constants, as evaluate() does it. Returns false for a division by zero.
bool apply_pure(Op op, const double* a, double& out, EvalError& err)
{
    switch (op) {
    case Op::Neg: out = -a[0]; return true;
    case Op::Not: out = a[0] == 0.0 ? 1.0 : 0.0; return true;
    case Op::Add: out = a[0] + a[1]; return true;
    case Op::Sub: out = a[0] - a[1]; return true;
    case Op::Mul: out = a[0] * a[1]; return true;
    case Op::Div:
        if (a[1] == 0.0) { err = EvalError::DivisionByZero; return false; }
        out = a[0] / a[1];
        return true;
    case Op::Mod:
        if (a[1] == 0.0) { err = EvalError::ModuloByZero; return false; }
        out = std::fmod(a[0], a[1]);
        return true;
    case Op::Pow:
    case Op::PowFn: out = std::pow(a[0], a[1]); return true;
    case Op::Lt: out = a[0] < a[1] ? 1.0 : 0.0; return true;
    case Op::Le: out = a[0] <= a[1] ? 1.0 : 0.0; return true;
    case Op::Gt: out = a[0] > a[1] ? 1.0 : 0.0; return true;
    case Op::Ge: out = a[0] >= a[1] ? 1.0 : 0.0; return true;
    case Op::Eq: out = a[0] == a[1] ? 1.0 : 0.0; return true;
    case Op::Ne: out = a[0] != a[1] ? 1.0 : 0.0; return true;
    case Op::ToBool: out = a[0] != 0.0 ? 1.0 : 0.0; return true;
    case Op::Sin: out = std::sin(a[0] * kDegToRad); return true;
    case Op::Cos: out = std::cos(a[0] * kDegToRad); return true;
    case Op::Tan: out = std::tan(a[0] * kDegToRad); return true;
    case Op::Asin: out = std::asin(a[0]) * kRadToDeg; return true;
    case Op::Acos: out = std::acos(a[0]) * kRadToDeg; return true;
    case Op::Atan: out = std::atan(a[0]) * kRadToDeg; return true;
    case Op::Atan2: out = std::atan2(a[0], a[1]) * kRadToDeg; return true;
    case Op::Exp: out = std::exp(a[0]); return true;
    case Op::Log: out = std::log(a[0]); return true;
    case Op::Sqrt: out = std::sqrt(a[0]); return true;
    case Op::Floor: out = std::floor(a[0]); return true;
    case Op::Ceil: out = std::ceil(a[0]); return true;
    case Op::Trunc: out = std::trunc(a[0]); return true;
    case Op::Fabs: out = std::fabs(a[0]); return true;
    case Op::Sign: out = sign_of(a[0]); return true;
    case Op::Min: out = std::min(a[0], a[1]); return true;
    case Op::Max: out = std::max(a[0], a[1]); return true;
    default: return false;
    }
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Evaluation

double keyed_uniform(std::uint64_t seed, std::uint64_t step_key, std::uint64_t position, std::uint32_t draw)
{
    return unit_interval(mix(mix(mix(seed, step_key), position), draw));
}

const char* eval_error_text(EvalError e)
{
    switch (e) {
    case EvalError::DivisionByZero: return "division by zero";
    case EvalError::ModuloByZero: return "remainder (%) of a division by zero";
    default: return "no error";
    }
}

EvalError evaluate(const std::vector<Instr>& code, const Expr& e, EvalContext& ctx, double& out)
{
    if (e.constant) {
        out = e.value;
        return EvalError::None;
    }
    double stack[kMaxExprStack + 1];
    std::uint32_t sp = 0; // number of values
    const Instr* const base = code.data() + e.first;
    const std::uint32_t n = e.count;
    EvalError err = EvalError::None;
    for (std::uint32_t pc = 0; pc < n; ++pc) {
        const Instr& in = base[pc];
        switch (in.op) {
        case Op::Const: stack[sp++] = in.value; break;
        case Op::Var: stack[sp++] = ctx.vars[in.arg]; break;
        case Op::Neg: stack[sp - 1] = -stack[sp - 1]; break;
        case Op::Not: stack[sp - 1] = stack[sp - 1] == 0.0 ? 1.0 : 0.0; break;
        case Op::ToBool: stack[sp - 1] = stack[sp - 1] != 0.0 ? 1.0 : 0.0; break;
        case Op::Add: --sp; stack[sp - 1] += stack[sp]; break;
        case Op::Sub: --sp; stack[sp - 1] -= stack[sp]; break;
        case Op::Mul: --sp; stack[sp - 1] *= stack[sp]; break;
        case Op::Div:
            --sp;
            if (stack[sp] == 0.0) return EvalError::DivisionByZero;
            stack[sp - 1] /= stack[sp];
            break;
        case Op::Lt: --sp; stack[sp - 1] = stack[sp - 1] < stack[sp] ? 1.0 : 0.0; break;
        case Op::Le: --sp; stack[sp - 1] = stack[sp - 1] <= stack[sp] ? 1.0 : 0.0; break;
        case Op::Gt: --sp; stack[sp - 1] = stack[sp - 1] > stack[sp] ? 1.0 : 0.0; break;
        case Op::Ge: --sp; stack[sp - 1] = stack[sp - 1] >= stack[sp] ? 1.0 : 0.0; break;
        case Op::Eq: --sp; stack[sp - 1] = stack[sp - 1] == stack[sp] ? 1.0 : 0.0; break;
        case Op::Ne: --sp; stack[sp - 1] = stack[sp - 1] != stack[sp] ? 1.0 : 0.0; break;
        case Op::AndJump:
            if (stack[sp - 1] == 0.0) {
                stack[sp - 1] = 0.0;
                pc += in.arg - 1;
            } else {
                --sp;
            }
            break;
        case Op::OrJump:
            if (stack[sp - 1] != 0.0) {
                stack[sp - 1] = 1.0;
                pc += in.arg - 1;
            } else {
                --sp;
            }
            break;
        case Op::JumpIfFalse:
            --sp;
            if (stack[sp] == 0.0) pc += in.arg - 1;
            break;
        case Op::Jump: pc += in.arg - 1; break;
        case Op::Ran: {
            const double u = keyed_uniform(ctx.seed, ctx.step_key, ctx.position, ctx.draws++);
            stack[sp - 1] *= u;
            break;
        }
        case Op::NRan: {
            --sp;
            const double u1 = 1.0 - keyed_uniform(ctx.seed, ctx.step_key, ctx.position, ctx.draws++);
            const double u2 = keyed_uniform(ctx.seed, ctx.step_key, ctx.position, ctx.draws++);
            const double z = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2);
            stack[sp - 1] = stack[sp - 1] + stack[sp] * z;
            break;
        }
        case Op::Inside: {
            sp -= 2;
            const glm::dvec3 p(stack[sp - 1], stack[sp], stack[sp + 1]);
            stack[sp - 1] = (ctx.environment == nullptr || ctx.environment->inside(p)) ? 1.0 : 0.0;
            break;
        }
        case Op::Stub:
            sp -= in.argc;
            stack[sp++] = in.value;
            break;
        default: {
            // Pure functions of one or two arguments.
            const bool two = in.op == Op::Atan2 || in.op == Op::Min || in.op == Op::Max ||
                             in.op == Op::PowFn || in.op == Op::Pow || in.op == Op::Mod;
            if (two) --sp;
            double r = 0.0;
            if (!apply_pure(in.op, &stack[sp - 1], r, err)) return err;
            stack[sp - 1] = r;
            break;
        }
        }
    }
    out = stack[0];
    return EvalError::None;
}

// ---------------------------------------------------------------------------------------------
// Source positions

SourceText::SourceText(std::string_view text, std::string name) : text_(text), name_(std::move(name))
{
    line_starts_.push_back(0);
    for (std::size_t i = 0; i < text_.size(); ++i)
        if (text_[i] == '\n') line_starts_.push_back(i + 1);
}

std::pair<std::size_t, std::size_t> SourceText::line_col(std::size_t offset) const
{
    const auto it = std::upper_bound(line_starts_.begin(), line_starts_.end(), offset);
    const std::size_t line = static_cast<std::size_t>(it - line_starts_.begin());
    return {line, offset - line_starts_[line - 1] + 1};
}

std::string SourceText::where(std::size_t offset) const
{
    const auto [line, col] = line_col(offset);
    return name_ + ":" + std::to_string(line) + ":" + std::to_string(col) + ": ";
}

void SourceText::fail(std::size_t offset, const std::string& message) const
{
    throw InvalidInput(where(offset) + message);
}

// ---------------------------------------------------------------------------------------------
// Compilation

ExprCompiler::ExprCompiler(const SourceText& source, std::vector<Instr>& code,
                           std::unordered_map<std::string, Define>& defines,
                           std::function<void(std::size_t, const std::string&)> warn)
    : src_(source), code_(code), defines_(defines), warn_(std::move(warn)), max_tokens_(max_expr_tokens(source.text().size()))
{
}

ExprCompiler::Token ExprCompiler::peek(const Cursor& c) const
{
    if (c.pos == cache_pos_ && c.end == cache_end_) return cache_token_;
    Cursor copy = c;
    cache_token_ = lex(copy);
    cache_pos_ = c.pos;
    cache_end_ = c.end;
    cache_next_ = copy.pos;
    return cache_token_;
}

ExprCompiler::Token ExprCompiler::next(Cursor& c)
{
    if (++tokens_ > max_tokens_)
        src_.fail(c.pos, "the expressions are too large to compile (#define expansions past " +
                             std::to_string(max_tokens_) + " tokens)");
    if (c.pos == cache_pos_ && c.end == cache_end_) {
        c.pos = cache_next_;
        return cache_token_;
    }
    return lex(c);
}

ExprCompiler::Token ExprCompiler::lex(Cursor& c) const
{
    const std::string_view t = src_.text();
    while (c.pos < c.end && (t[c.pos] == ' ' || t[c.pos] == '\t' || t[c.pos] == '\r' || t[c.pos] == '\n'))
        ++c.pos;
    Token tok;
    tok.begin = c.pos;
    if (c.pos >= c.end) {
        tok.kind = Tok::End;
        tok.end = c.pos;
        return tok;
    }
    const char ch = t[c.pos];
    auto one = [&](Tok k) {
        tok.kind = k;
        tok.end = ++c.pos;
        tok.text = t.substr(tok.begin, 1);
        return tok;
    };
    if (is_digit(ch) || (ch == '.' && c.pos + 1 < c.end && is_digit(t[c.pos + 1]))) {
        std::size_t p = c.pos;
        while (p < c.end && is_digit(t[p])) ++p;
        if (p < c.end && t[p] == '.') {
            ++p;
            while (p < c.end && is_digit(t[p])) ++p;
        }
        if (p < c.end && (t[p] == 'e' || t[p] == 'E')) {
            std::size_t q = p + 1;
            if (q < c.end && (t[q] == '+' || t[q] == '-')) ++q;
            if (q < c.end && is_digit(t[q])) {
                while (q < c.end && is_digit(t[q])) ++q;
                p = q;
            }
        }
        tok.kind = Tok::Number;
        tok.end = p;
        tok.text = t.substr(c.pos, p - c.pos);
        const auto r = std::from_chars(t.data() + c.pos, t.data() + p, tok.number);
        if (r.ec == std::errc::result_out_of_range) src_.fail(c.pos, "number out of range: '" + std::string(tok.text) + "'");
        if (r.ec != std::errc() || r.ptr != t.data() + p) src_.fail(c.pos, "malformed number '" + std::string(tok.text) + "'");
        c.pos = p;
        return tok;
    }
    if (is_name_start(ch)) {
        std::size_t p = c.pos;
        while (p < c.end && is_name_char(t[p])) ++p;
        tok.kind = Tok::Name;
        tok.end = p;
        tok.text = t.substr(c.pos, p - c.pos);
        c.pos = p;
        return tok;
    }
    if (ch == '"') {
        std::size_t p = c.pos + 1;
        while (p < c.end && t[p] != '"' && t[p] != '\n') ++p;
        if (p >= c.end || t[p] != '"') src_.fail(c.pos, "unterminated string");
        tok.kind = Tok::String;
        tok.end = p + 1;
        tok.text = t.substr(c.pos, p + 1 - c.pos);
        c.pos = p + 1;
        return tok;
    }
    switch (ch) {
    case '(': return one(Tok::LParen);
    case ')': return one(Tok::RParen);
    case ',': return one(Tok::Comma);
    case '?': return one(Tok::Question);
    case ':': return one(Tok::Colon);
    default: break;
    }
    auto two = [&](std::string_view op) {
        return c.pos + 1 < c.end && t[c.pos] == op[0] && t[c.pos + 1] == op[1];
    };
    for (const std::string_view op : {"&&", "||", "==", "!=", "<>", "<=", ">="}) {
        if (two(op)) {
            tok.kind = Tok::Op;
            tok.text = t.substr(c.pos, 2);
            c.pos += 2;
            tok.end = c.pos;
            return tok;
        }
    }
    switch (ch) {
    case '+': case '-': case '*': case '/': case '%': case '^': case '<': case '>': case '!':
        return one(Tok::Op);
    default: break;
    }
    // Anything else ends the expression; the caller decides whether that is an error.
    tok.kind = Tok::End;
    tok.end = c.pos;
    tok.text = t.substr(c.pos, 1);
    return tok;
}

void ExprCompiler::expect(Cursor& c, Tok kind, const char* what)
{
    const Token t = next(c);
    if (t.kind != kind) {
        std::string found;
        if (t.kind == Tok::End && t.begin >= c.end) {
            found = "the end of the expression";
        } else {
            found = "'";
            found.append(t.text);
            found += "'";
        }
        src_.fail(t.begin, std::string("expected ") + what + ", found " + found);
    }
}

void ExprCompiler::emit(Op op, std::uint32_t arg, double value, std::uint8_t argc)
{
    if (code_.size() >= kMaxCodeSize) src_.fail(0, "the expressions are too large (over 4 million instructions)");
    Instr in;
    in.op = op;
    in.arg = arg;
    in.value = value;
    in.argc = argc;
    code_.push_back(in);
}

void ExprCompiler::adjust_depth(int delta)
{
    depth_ = static_cast<std::uint32_t>(static_cast<int>(depth_) + delta);
    max_depth_ = std::max(max_depth_, depth_);
}

void ExprCompiler::fold_to(std::size_t start, double value)
{
    code_.resize(start);
    emit(Op::Const, 0, value);
}

Expr ExprCompiler::compile(std::size_t& pos, std::size_t end)
{
    Cursor c{pos, end};
    depth_ = 0;
    max_depth_ = 0;
    const Token first = peek(c);
    const std::size_t start = code_.size();
    if (first.kind == Tok::End) src_.fail(first.begin, "expected an expression");
    parse_ternary(c, 0);
    if (max_depth_ > kMaxExprStack) src_.fail(first.begin, "expression too deeply nested");
    Expr e;
    e.first = static_cast<std::uint32_t>(start);
    e.count = static_cast<std::uint32_t>(code_.size() - start);
    e.max_stack = max_depth_;
    e.offset = first.begin;
    if (e.count == 1 && code_[start].op == Op::Const) {
        e.constant = true;
        e.value = code_[start].value;
    }
    // Skip trailing blanks so the caller sees the delimiter.
    const std::string_view t = src_.text();
    while (c.pos < c.end && (t[c.pos] == ' ' || t[c.pos] == '\t' || t[c.pos] == '\r' || t[c.pos] == '\n')) ++c.pos;
    pos = c.pos;
    return e;
}

Expr ExprCompiler::compile_all(std::size_t begin, std::size_t end)
{
    std::size_t pos = begin;
    const Expr e = compile(pos, end);
    if (pos < end) src_.fail(pos, "unexpected '" + std::string(src_.text().substr(pos, 1)) + "' in an expression");
    return e;
}

double ExprCompiler::evaluate_constant(const Expr& e, std::size_t offset)
{
    EvalContext ctx;
    double v = 0.0;
    const EvalError err = evaluate(code_, e, ctx, v);
    if (err != EvalError::None) src_.fail(offset, eval_error_text(err));
    return v;
}

void ExprCompiler::check_define(const std::string& name)
{
    const auto it = defines_.find(name);
    if (it == defines_.end()) return;
    // Compiled in a scope of its own, then dropped: names it does not know may be formal
    // parameters where it is used, so only recursion and constant errors are reported here.
    const std::size_t start = code_.size();
    const auto* saved = scope_;
    scope_ = nullptr;
    lenient_ = true;
    try {
        Cursor c{it->second.begin, it->second.end};
        depth_ = 0;
        max_depth_ = 0;
        if (peek(c).kind == Tok::End) src_.fail(it->second.name_offset, "#define " + name + " has no value");
        parse_name(Token{Tok::Name, it->second.name_offset, it->second.name_offset + name.size(), 0.0, name}, 0);
    } catch (...) {
        lenient_ = false;
        scope_ = saved;
        code_.resize(start);
        throw;
    }
    lenient_ = false;
    scope_ = saved;
    code_.resize(start);
}

// Precedence levels of binary operators, lowest first (cpfg's lsys_input.y).
namespace {
int binary_level(std::string_view op)
{
    if (op == "||") return 0;
    if (op == "&&") return 1;
    if (op == "==" || op == "!=" || op == "<>") return 2;
    if (op == "<" || op == "<=" || op == ">" || op == ">=") return 3;
    if (op == "+" || op == "-") return 4;
    if (op == "*" || op == "/" || op == "%") return 5;
    if (op == "^") return 6;
    return -1;
}
constexpr int kLevels = 7;

Op binary_op(std::string_view op)
{
    if (op == "==") return Op::Eq;
    if (op == "!=" || op == "<>") return Op::Ne;
    if (op == "<") return Op::Lt;
    if (op == "<=") return Op::Le;
    if (op == ">") return Op::Gt;
    if (op == ">=") return Op::Ge;
    if (op == "+") return Op::Add;
    if (op == "-") return Op::Sub;
    if (op == "*") return Op::Mul;
    if (op == "/") return Op::Div;
    if (op == "%") return Op::Mod;
    return Op::Pow;
}
} // namespace

std::size_t ExprCompiler::parse_ternary(Cursor& c, int depth)
{
    if (depth > kMaxExprNesting) src_.fail(c.pos, "expression nested too deeply (over " + std::to_string(kMaxExprNesting) + " levels)");
    const std::size_t start = parse_binary(c, 0, depth + 1);
    if (peek(c).kind != Tok::Question) return start;
    next(c);
    const bool cond_const = is_constant_from(start);
    const double cond_value = cond_const ? code_[start].value : 0.0;
    const std::size_t jif = code_.size();
    emit(Op::JumpIfFalse);
    adjust_depth(-1);
    const std::uint32_t base_depth = depth_;
    const std::size_t t_start = parse_ternary(c, depth + 1);
    expect(c, Tok::Colon, "':' of '?:'");
    const std::size_t jmp = code_.size();
    emit(Op::Jump);
    depth_ = base_depth;
    const std::size_t f_start = parse_ternary(c, depth + 1);
    code_[jif].arg = static_cast<std::uint32_t>(f_start - jif);
    code_[jmp].arg = static_cast<std::uint32_t>(code_.size() - jmp);
    if (cond_const) {
        // Keep one branch: jumps are relative, so the block moves as it is.
        std::vector<Instr> keep;
        if (cond_value != 0.0)
            keep.assign(code_.begin() + static_cast<std::ptrdiff_t>(t_start), code_.begin() + static_cast<std::ptrdiff_t>(jmp));
        else
            keep.assign(code_.begin() + static_cast<std::ptrdiff_t>(f_start), code_.end());
        code_.resize(start);
        code_.insert(code_.end(), keep.begin(), keep.end());
    }
    return start;
}

std::size_t ExprCompiler::parse_binary(Cursor& c, int level, int depth)
{
    if (level >= kLevels) return parse_unary(c, depth);
    const std::size_t start = parse_binary(c, level + 1, depth);
    for (;;) {
        const Token t = peek(c);
        if (t.kind != Tok::Op || binary_level(t.text) != level) return start;
        next(c);
        if (level == 0 || level == 1) {
            // Short-circuit || and &&, as C.
            const bool is_and = level == 1;
            const bool left_const = is_constant_from(start);
            const double left_value = left_const ? code_[start].value : 0.0;
            const std::size_t j = code_.size();
            emit(is_and ? Op::AndJump : Op::OrJump);
            adjust_depth(-1);
            const std::size_t right = parse_binary(c, level + 1, depth);
            emit(Op::ToBool);
            code_[j].arg = static_cast<std::uint32_t>(code_.size() - j);
            if (left_const) {
                const bool decided = is_and ? left_value == 0.0 : left_value != 0.0;
                if (decided) {
                    fold_to(start, is_and ? 0.0 : 1.0);
                } else {
                    std::vector<Instr> keep(code_.begin() + static_cast<std::ptrdiff_t>(right), code_.end());
                    code_.resize(start);
                    code_.insert(code_.end(), keep.begin(), keep.end());
                    if (code_.size() == start + 2 && code_[start].op == Op::Const)
                        fold_to(start, code_[start].value != 0.0 ? 1.0 : 0.0);
                }
            }
            continue;
        }
        const std::size_t right = parse_binary(c, level + 1, depth);
        const Op op = binary_op(t.text);
        const bool both_const = right == start + 1 && code_[start].op == Op::Const && is_constant_from(right);
        if (both_const) {
            const double a[2] = {code_[start].value, code_[right].value};
            double r = 0.0;
            EvalError err = EvalError::None;
            if (!apply_pure(op, a, r, err)) src_.fail(t.begin, eval_error_text(err));
            adjust_depth(-1);
            fold_to(start, r);
        } else {
            emit(op);
            adjust_depth(-1);
        }
    }
}

std::size_t ExprCompiler::parse_unary(Cursor& c, int depth)
{
    if (depth > kMaxExprNesting) src_.fail(c.pos, "expression nested too deeply (over " + std::to_string(kMaxExprNesting) + " levels)");
    const Token t = peek(c);
    if (t.kind == Tok::Op && (t.text == "-" || t.text == "!" || t.text == "+")) {
        next(c);
        const std::size_t start = parse_unary(c, depth + 1);
        if (t.text == "+") return start;
        const Op op = t.text == "-" ? Op::Neg : Op::Not;
        if (is_constant_from(start)) {
            double r = 0.0;
            EvalError err = EvalError::None;
            apply_pure(op, &code_[start].value, r, err);
            fold_to(start, r);
        } else {
            emit(op);
        }
        return start;
    }
    return parse_primary(c, depth);
}

std::size_t ExprCompiler::parse_primary(Cursor& c, int depth)
{
    const Token t = next(c);
    const std::size_t start = code_.size();
    switch (t.kind) {
    case Tok::Number:
        emit(Op::Const, 0, t.number);
        adjust_depth(1);
        return start;
    case Tok::LParen:
        parse_ternary(c, depth + 1);
        expect(c, Tok::RParen, "')'");
        return start;
    case Tok::Name:
        if (peek(c).kind == Tok::LParen) return parse_call(c, t, depth);
        return parse_name(t, depth);
    case Tok::String: src_.fail(t.begin, "a string is allowed only as an argument of printf");
    case Tok::End:
        if (t.begin >= c.end) src_.fail(t.begin, "expected a value, found the end of the expression");
        if (t.text == "=") src_.fail(t.begin, "assignments ('=') are not supported in expressions");
        if (t.text == "&") src_.fail(t.begin, "'&' (an address) is not supported in expressions; '&&' is 'and'");
        src_.fail(t.begin, "unexpected '" + std::string(t.text) + "' in an expression");
    default: src_.fail(t.begin, "expected a value, found '" + std::string(t.text) + "'");
    }
}

std::size_t ExprCompiler::parse_call(Cursor& c, const Token& name, int depth)
{
    const std::size_t start = code_.size();
    const FunctionInfo* fn = nullptr;
    for (const FunctionInfo& f : kFunctions)
        if (name.text == f.name) fn = &f;
    const StubInfo* stub = nullptr;
    for (const StubInfo& s : kStubs)
        if (name.text == s.name) stub = &s;
    if (fn == nullptr && stub == nullptr) src_.fail(name.begin, "unknown function '" + std::string(name.text) + "'");
    expect(c, Tok::LParen, "'('");
    std::vector<std::size_t> args;
    if (peek(c).kind != Tok::RParen) {
        for (;;) {
            if (stub != nullptr && peek(c).kind == Tok::String) {
                next(c);
                emit(Op::Const, 0, 0.0);
                adjust_depth(1);
                args.push_back(code_.size() - 1);
            } else {
                args.push_back(parse_ternary(c, depth + 1));
            }
            if (args.size() > 64) src_.fail(name.begin, "too many arguments");
            if (peek(c).kind != Tok::Comma) break;
            next(c);
        }
    }
    expect(c, Tok::RParen, "')' closing the call");
    const int argc = static_cast<int>(args.size());
    if (stub != nullptr) {
        const std::string n(name.text);
        if (std::find(warned_functions_.begin(), warned_functions_.end(), n) == warned_functions_.end()) {
            warned_functions_.push_back(n);
            char buf[64];
            auto r = std::to_chars(buf, buf + sizeof buf, stub->value);
            warn_(name.begin, "cpfg's function '" + n + "' is not supported; it gives " + std::string(buf, r.ptr));
        }
        code_.resize(start);
        depth_ -= static_cast<std::uint32_t>(argc);
        emit(Op::Const, 0, stub->value);
        adjust_depth(1);
        return start;
    }
    if (argc != fn->arity)
        src_.fail(name.begin, std::string(fn->name) + "() takes " + std::to_string(fn->arity) +
                                  (fn->arity == 1 ? " argument" : " arguments") + ", not " + std::to_string(argc));
    bool all_const = fn->pure;
    for (int i = 0; i < argc && all_const; ++i) {
        const std::size_t s = args[static_cast<std::size_t>(i)];
        const std::size_t e = i + 1 < argc ? args[static_cast<std::size_t>(i) + 1] : code_.size();
        all_const = e == s + 1 && code_[s].op == Op::Const;
    }
    if (all_const) {
        double a[3] = {0.0, 0.0, 0.0};
        for (int i = 0; i < argc; ++i) a[i] = code_[args[static_cast<std::size_t>(i)]].value;
        double r = 0.0;
        EvalError err = EvalError::None;
        apply_pure(fn->op, a, r, err);
        depth_ -= static_cast<std::uint32_t>(argc);
        adjust_depth(1);
        fold_to(start, r);
        return start;
    }
    emit(fn->op);
    depth_ -= static_cast<std::uint32_t>(argc);
    adjust_depth(1);
    return start;
}

std::size_t ExprCompiler::parse_name(const Token& name, int depth)
{
    const std::size_t start = code_.size();
    const std::string n(name.text);
    if (scope_ != nullptr) {
        const auto it = scope_->find(n);
        if (it != scope_->end()) {
            emit(Op::Var, it->second);
            adjust_depth(1);
            return start;
        }
    }
    const auto d = defines_.find(n);
    if (d != defines_.end()) {
        Define& def = d->second;
        if (def.expanding) src_.fail(def.name_offset, "recursive #define '" + n + "'");
        if (depth > kMaxExprNesting) src_.fail(name.begin, "expression nested too deeply (over " + std::to_string(kMaxExprNesting) + " levels)");
        def.expanding = true;
        try {
            Cursor sub{def.begin, def.end};
            if (peek(sub).kind == Tok::End) src_.fail(def.name_offset, "#define " + n + " has no value");
            parse_ternary(sub, depth + 1);
            const Token rest = next(sub);
            if (rest.kind != Tok::End || rest.begin < def.end)
                src_.fail(rest.begin, "unexpected '" + std::string(rest.text) + "' in #define " + n);
        } catch (...) {
            def.expanding = false;
            throw;
        }
        def.expanding = false;
        return start;
    }
    if (lenient_) {
        // Checking a #define alone: an unknown name may be a formal parameter where it is used.
        emit(Op::Var, 0);
        adjust_depth(1);
        return start;
    }
    src_.fail(name.begin, "undefined name '" + n + "' (not a parameter of the production nor a #define)");
}

} // namespace lobe::lsystem::detail
