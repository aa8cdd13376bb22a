// Parallel rewriting, decomposition, homomorphism, the cut symbol and the word's text form:
// lsystem.h.
//
// A step runs in two passes over the word: the first picks a production for every module
// (context, condition, weights) and counts what the new word will hold, the second writes it
// into storage allocated once, after the count was checked against the limits. A production
// whose successor has only constant parameters copies a block built when the file was read.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>

#include "core/errors.h"
#include "core/random.h"
#include "growth/lsystem/expr.h"
#include "growth/lsystem/lsystem.h"
#include "growth/lsystem/lsystem_impl.h"

namespace lobe::lsystem {

using detail::EvalContext;
using detail::EvalError;
using detail::Expr;
using detail::PatternModule;
using detail::Production;
using detail::ProductionSet;
using detail::SymbolRule;

// ---------------------------------------------------------------------------------------------
// Word, LSystem

void Word::push(SymbolId symbol, std::span<const double> values)
{
    if (values.size() > kMaxModuleParams)
        throw InvalidInput("a module with " + std::to_string(values.size()) + " parameters (at most 255)");
    Module m;
    m.symbol = symbol;
    m.param_count = static_cast<std::uint16_t>(values.size());
    m.first_param = static_cast<std::uint32_t>(params.size());
    modules.push_back(m);
    params.insert(params.end(), values.begin(), values.end());
}

LSystem::LSystem() : impl_(std::make_shared<Impl>()) {}
LSystem::LSystem(std::shared_ptr<const Impl> impl) : impl_(impl ? std::move(impl) : std::make_shared<Impl>()) {}

const std::string& LSystem::source_name() const { return impl_->source_name; }
int LSystem::derivation_length() const { return impl_->derivation_length; }
const Word& LSystem::axiom() const { return impl_->axiom; }
int LSystem::find_symbol(std::string_view name) const
{
    const auto it = impl_->symbol_ids.find(std::string(name));
    return it == impl_->symbol_ids.end() ? -1 : static_cast<int>(it->second);
}
std::string_view LSystem::symbol_name(SymbolId id) const
{
    return id < impl_->symbol_names.size() ? std::string_view(impl_->symbol_names[id]) : std::string_view();
}
std::size_t LSystem::symbol_count() const { return impl_->symbol_names.size(); }
bool LSystem::has_queries() const { return impl_->has_queries; }

// ---------------------------------------------------------------------------------------------
// Indexing

void detail::index_productions(ProductionSet& set, std::size_t symbol_count)
{
    set.rules.assign(symbol_count, SymbolRule{});
    set.candidates.clear();
    std::vector<std::vector<std::uint32_t>> cs(symbol_count);
    std::vector<std::vector<std::uint32_t>> cf(symbol_count);
    for (std::uint32_t i = 0; i < set.productions.size(); ++i) {
        const Production& p = set.productions[i];
        (p.is_context_sensitive() ? cs : cf)[p.pred.symbol].push_back(i);
    }
    for (std::size_t s = 0; s < symbol_count; ++s) {
        if (cs[s].empty() && cf[s].empty()) continue;
        SymbolRule& r = set.rules[s];
        r.first = static_cast<std::uint32_t>(set.candidates.size());
        r.cs_count = static_cast<std::uint32_t>(cs[s].size());
        r.cf_count = static_cast<std::uint32_t>(cf[s].size());
        for (const std::uint32_t i : cs[s]) {
            set.candidates.push_back(i);
            r.cs_stochastic = r.cs_stochastic || set.productions[i].has_probability;
        }
        for (const std::uint32_t i : cf[s]) {
            set.candidates.push_back(i);
            r.cf_stochastic = r.cf_stochastic || set.productions[i].has_probability;
        }
        r.kind = SymbolRule::General;
        if (cs[s].empty() && cf[s].size() == 1) {
            const Production& p = set.productions[cf[s][0]];
            if (!p.has_condition && !p.has_probability && p.constant_successor) {
                r.kind = SymbolRule::ConstantBlock;
                r.pred_params = p.pred.param_count;
                r.production = cf[s][0];
                r.block_modules = static_cast<std::uint32_t>(p.block.size());
                r.block_params = static_cast<std::uint32_t>(p.block_params.size());
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Rewriting

namespace {

enum Section : std::uint64_t { kMain = 0, kDecomposition = 1, kHomomorphism = 2 };

std::string number_text(double v)
{
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

void append_module(std::string& out, const LSystem::Impl& sys, const Word& w, const Module& m)
{
    out += m.symbol < sys.symbol_names.size() ? sys.symbol_names[m.symbol] : std::string("<") + std::to_string(m.symbol) + ">";
    if (m.param_count == 0) return;
    out += '(';
    char buf[32];
    for (std::uint32_t k = 0; k < m.param_count; ++k) {
        if (k > 0) out += ',';
        const auto r = std::to_chars(buf, buf + sizeof buf, w.params[m.first_param + k]);
        out.append(buf, r.ptr);
    }
    out += ')';
}

std::string module_text(const LSystem::Impl& sys, const Word& w, std::size_t i)
{
    std::string s;
    append_module(s, sys, w, w.modules[i]);
    if (s.size() > 80) s = s.substr(0, 77) + "...";
    return s;
}

/// One rewriting pass of a production set over a word; keeps its scratch between calls.
class Rewriter {
public:
    Rewriter(const LSystem::Impl& sys, const DeriveOptions& options) : sys_(sys), opt_(options)
    {
        max_modules_ = std::min(options.max_modules, kMaxModules);
        max_params_ = std::min(options.max_param_values, kMaxParamValues);
        max_ops_ = options.max_operations;
    }

    /// Rewrites `in` into `out` with `set`. `live_in` (optional) marks the modules that may be
    /// rewritten; `live_out` (optional) gets the modules a production wrote. Returns how many
    /// modules were rewritten. \throw InvalidInput past the limits or for a failed evaluation.
    std::size_t rewrite(const ProductionSet& set, Section section, int step, int pass, const Word& in, Word& out,
                        const std::vector<std::uint8_t>* live_in, std::vector<std::uint8_t>* live_out, std::uint64_t seed);

    std::size_t max_modules() const { return max_modules_; }
    std::size_t max_params() const { return max_params_; }

private:
    bool match_context(const Production& p, std::size_t i, std::uint32_t* pos);
    void build_context_tables();
    void bind(const Production& p, std::size_t i, const std::uint32_t* pos, double* vars) const;
    std::int32_t select(const ProductionSet& set, const SymbolRule& r, std::size_t i);
    [[noreturn]] void fail_eval(EvalError err, const Production& p, std::size_t i, const char* what) const;
    void check_operations() const
    {
        if (ops_ > max_ops_)
            throw InvalidInput(sys_.source_name + ": step " + std::to_string(step_) + ": the derivation went past " +
                               std::to_string(max_ops_) +
                               " operations (its productions evaluate too much over too large a word)");
    }

    const LSystem::Impl& sys_;
    const DeriveOptions& opt_;
    std::size_t max_modules_ = 0;
    std::size_t max_params_ = 0;
    std::uint64_t max_ops_ = 0;
    std::uint64_t ops_ = 0; ///< work done so far (modules and instructions)
    // Per call.
    const Word* in_ = nullptr;
    const ProductionSet* set_ = nullptr;
    Section section_ = kMain;
    int step_ = 0;
    EvalContext ctx_;
    std::vector<std::int32_t> choice_;
    // Context tables (rewrite() builds them when the set has context-sensitive productions).
    std::vector<std::int32_t> left_;
    std::vector<std::int32_t> right_;
    std::vector<std::int32_t> next_;
    std::vector<std::int32_t> open_;
    std::vector<double> vars_;
    std::vector<std::uint32_t> pos_;
    std::vector<std::uint32_t> matched_;
    std::vector<double> weights_;
};

void Rewriter::fail_eval(EvalError err, const Production& p, std::size_t i, const char* what) const
{
    throw InvalidInput(sys_.source_name + ": step " + std::to_string(step_) + ": " + detail::eval_error_text(err) +
                       " in the " + what + " of the production at " + p.where + ", rewriting module " +
                       std::to_string(i + 1) + " " + module_text(sys_, *in_, i));
}

bool Rewriter::match_context(const Production& p, std::size_t i, std::uint32_t* pos)
{
    // O(context length): the tables built in rewrite() jump over ignored modules and branches.
    const Module* mods = in_->modules.data();
    const std::int32_t n = static_cast<std::int32_t>(in_->modules.size());
    const SymbolId lb = sys_.left_bracket;
    ops_ += p.left.size() + p.right.size();
    std::int32_t at = static_cast<std::int32_t>(i) - 1;
    for (std::size_t k = p.left.size(); k-- > 0;) {
        if (at < 0) return false;
        at = left_[static_cast<std::size_t>(at)];
        if (at < 0) return false;
        const Module& m = mods[at];
        if (m.symbol != p.left[k].symbol || m.param_count != p.left[k].param_count) return false;
        pos[k] = static_cast<std::uint32_t>(at);
        --at;
    }
    at = static_cast<std::int32_t>(i) + 1;
    for (std::size_t k = 0; k < p.right.size(); ++k) {
        const PatternModule& want = p.right[k];
        if (at >= n) return false;
        // A right context skips whole branches unless it names one ('A > [B]C').
        at = (want.symbol == lb ? next_ : right_)[static_cast<std::size_t>(at)];
        if (at >= n) return false;
        const Module& m = mods[at];
        if (m.symbol != want.symbol || m.param_count != want.param_count) return false;
        pos[p.left.size() + k] = static_cast<std::uint32_t>(at);
        ++at;
    }
    return true;
}

void Rewriter::build_context_tables()
{
    const Module* mods = in_->modules.data();
    const std::size_t n = in_->modules.size();
    const auto sn = static_cast<std::int32_t>(n);
    const SymbolId lb = sys_.left_bracket;
    const SymbolId rb = sys_.right_bracket;
    const std::uint8_t* ignored = sys_.ignored.data();
    const std::size_t nsym = sys_.ignored.size();
    auto is_ignored = [&](SymbolId s) { return s < nsym && ignored[s] != 0; };
    // Matching brackets (in next_ for now); an unmatched '[' reaches the end, an unmatched ']'
    // the start.
    next_.assign(n, 0);
    open_.clear();
    for (std::size_t k = 0; k < n; ++k) {
        const SymbolId s = mods[k].symbol;
        if (s == lb && lb != kNoSymbol) {
            open_.push_back(static_cast<std::int32_t>(k));
            next_[k] = sn;
        } else if (s == rb && rb != kNoSymbol) {
            if (open_.empty()) {
                next_[k] = -1;
            } else {
                next_[k] = open_.back();
                next_[static_cast<std::size_t>(open_.back())] = static_cast<std::int32_t>(k);
                open_.pop_back();
            }
        }
    }
    // left_[p]: the module a left context meets walking left from p (inclusive): a branch's
    // first module sees the module before the branch; earlier branches are skipped whole.
    left_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
        const SymbolId s = mods[k].symbol;
        std::int32_t v = static_cast<std::int32_t>(k);
        if (s == rb && rb != kNoSymbol) {
            const std::int32_t open = next_[k];
            v = open <= 0 ? -1 : left_[static_cast<std::size_t>(open - 1)];
        } else if ((s == lb && lb != kNoSymbol) || is_ignored(s)) {
            v = k == 0 ? -1 : left_[k - 1];
        }
        left_[k] = v;
    }
    // right_[p]: the module a right context meets walking right from p, skipping branches.
    right_.resize(n);
    for (std::size_t k = n; k-- > 0;) {
        const SymbolId s = mods[k].symbol;
        std::int32_t v = static_cast<std::int32_t>(k);
        if (s == lb && lb != kNoSymbol) {
            const std::int32_t close = next_[k];
            v = close >= sn - 1 ? sn : right_[static_cast<std::size_t>(close) + 1];
        } else if (is_ignored(s) && s != rb) {
            v = k + 1 >= n ? sn : right_[k + 1];
        }
        right_[k] = v;
    }
    // next_[p]: the next module not ignored, branches not skipped.
    for (std::size_t k = n; k-- > 0;) {
        const SymbolId s = mods[k].symbol;
        next_[k] = (is_ignored(s) && s != lb && s != rb) ? (k + 1 >= n ? sn : next_[k + 1]) : static_cast<std::int32_t>(k);
    }
}

void Rewriter::bind(const Production& p, std::size_t i, const std::uint32_t* pos, double* vars) const
{
    const Word& w = *in_;
    const Module& m = w.modules[i];
    const double* src = w.params.data();
    for (std::uint32_t k = 0; k < p.pred.param_count; ++k) vars[p.pred.first_var + k] = src[m.first_param + k];
    for (std::size_t c = 0; c < p.left.size(); ++c) {
        const Module& cm = w.modules[pos[c]];
        for (std::uint32_t k = 0; k < p.left[c].param_count; ++k) vars[p.left[c].first_var + k] = src[cm.first_param + k];
    }
    for (std::size_t c = 0; c < p.right.size(); ++c) {
        const Module& cm = w.modules[pos[p.left.size() + c]];
        for (std::uint32_t k = 0; k < p.right[c].param_count; ++k) vars[p.right[c].first_var + k] = src[cm.first_param + k];
    }
}

std::int32_t Rewriter::select(const ProductionSet& set, const SymbolRule& r, std::size_t i)
{
    const Module& m = in_->modules[i];
    std::uint32_t* pos = pos_.data();
    double* vars = vars_.data();
    ctx_.vars = vars;
    ctx_.position = i;
    ctx_.draws = 0;
    // Context-sensitive productions first (the more specific ones), then context-free ones.
    for (int group = 0; group < 2; ++group) {
        const std::uint32_t first = group == 0 ? r.first : r.first + r.cs_count;
        const std::uint32_t count = group == 0 ? r.cs_count : r.cf_count;
        const bool stochastic = group == 0 ? r.cs_stochastic : r.cf_stochastic;
        if (count == 0) continue;
        matched_.clear();
        weights_.clear();
        double total = 0.0;
        for (std::uint32_t c = 0; c < count; ++c) {
            const std::uint32_t pi = set.candidates[first + c];
            const Production& p = set.productions[pi];
            if (p.pred.param_count != m.param_count) continue;
            if (group == 0 && !match_context(p, i, pos)) continue;
            bind(p, i, pos, vars);
            if (p.has_condition) {
                ops_ += p.condition.count;
                double v = 0.0;
                const EvalError err = detail::evaluate(sys_.code, p.condition, ctx_, v);
                if (err != EvalError::None) fail_eval(err, p, i, "condition");
                if (v == 0.0) continue;
            }
            if (!stochastic) return static_cast<std::int32_t>(pi);
            double weight = 1.0;
            if (p.has_probability) {
                ops_ += p.probability.count;
                const EvalError err = detail::evaluate(sys_.code, p.probability, ctx_, weight);
                if (err != EvalError::None) fail_eval(err, p, i, "probability");
                if (!(weight >= 0.0) || !std::isfinite(weight))
                    throw InvalidInput(sys_.source_name + ": step " + std::to_string(step_) + ": the probability of the production at " +
                                       p.where + " is " + number_text(weight) + " (not a finite number of at least 0), rewriting module " +
                                       std::to_string(i + 1) + " " + module_text(sys_, *in_, i));
            }
            if (weight <= 0.0) continue;
            matched_.push_back(pi);
            weights_.push_back(weight);
            total += weight;
        }
        if (matched_.empty()) continue;
        // cpfg normalises the weights of the productions that apply.
        const double u = detail::keyed_uniform(opt_.seed ^ 0x5EEDull, ctx_.step_key, i, 0xFFFFFFFFu) * total;
        std::size_t pick = matched_.size() - 1;
        double acc = 0.0;
        for (std::size_t k = 0; k < matched_.size(); ++k) {
            acc += weights_[k];
            if (u < acc) {
                pick = k;
                break;
            }
        }
        return static_cast<std::int32_t>(matched_[pick]);
    }
    return -1;
}

std::size_t Rewriter::rewrite(const ProductionSet& set, Section section, int step, int pass, const Word& in, Word& out,
                              const std::vector<std::uint8_t>* live_in, std::vector<std::uint8_t>* live_out,
                              std::uint64_t seed)
{
    in_ = &in;
    set_ = &set;
    section_ = section;
    step_ = step;
    ctx_ = EvalContext{};
    ctx_.seed = seed;
    ctx_.step_key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(step)) << 16) |
                    (static_cast<std::uint64_t>(pass) << 2) | section;
    ctx_.environment = opt_.environment;
    const std::size_t n = in.modules.size();
    const Module* mods = in.modules.data();
    const std::size_t nrules = set.rules.size();
    choice_.resize(n);
    vars_.resize(std::max<std::size_t>(set.max_vars, 1));
    std::size_t longest_context = 0;
    for (const Production& p : set.productions) longest_context = std::max(longest_context, p.left.size() + p.right.size());
    pos_.resize(std::max<std::size_t>(longest_context, 1));

    if (set.has_context) build_context_tables();

    // Pass 1: choose, and count.
    ops_ += n;
    check_operations();
    std::size_t total_modules = 0;
    std::size_t total_params = 0;
    std::size_t rewritten = 0;
    const Production* prods = set.productions.data();
    for (std::size_t i = 0; i < n; ++i) {
        const Module& m = mods[i];
        std::int32_t c = -1;
        if ((live_in == nullptr || (*live_in)[i]) && m.symbol < nrules) {
            const SymbolRule& r = set.rules[m.symbol];
            if (r.kind == SymbolRule::ConstantBlock) {
                if (m.param_count == r.pred_params) {
                    choice_[i] = static_cast<std::int32_t>(r.production);
                    total_modules += r.block_modules;
                    total_params += r.block_params;
                    ++rewritten;
                    continue;
                }
            } else if (r.kind == SymbolRule::General) {
                c = select(set, r, i);
                if (c >= 0) ops_ += prods[c].successor_cost;
                if (ops_ > max_ops_) check_operations();
            }
        }
        choice_[i] = c;
        if (c < 0) {
            total_modules += 1;
            total_params += m.param_count;
        } else {
            total_modules += prods[c].successor.size();
            total_params += prods[c].successor_param_count;
            ++rewritten;
        }
    }
    ops_ += total_modules;
    check_operations();
    if (total_modules > max_modules_)
        throw InvalidInput(sys_.source_name + ": step " + std::to_string(step) + ": the word would grow to " +
                           std::to_string(total_modules) + " modules, over the limit of " + std::to_string(max_modules_));
    if (total_params > max_params_)
        throw InvalidInput(sys_.source_name + ": step " + std::to_string(step) + ": the word would hold " +
                           std::to_string(total_params) + " parameter values, over the limit of " + std::to_string(max_params_));

    // Pass 2: write.
    // Cleared first, so that growing the storage copies nothing.
    out.modules.clear();
    out.params.clear();
    out.modules.resize(total_modules);
    out.params.resize(total_params);
    if (live_out != nullptr) {
        live_out->clear();
        live_out->resize(total_modules);
    }
    Module* om = out.modules.data();
    double* op = out.params.data();
    const double* ip = in.params.data();
    std::uint8_t* lo = live_out != nullptr ? live_out->data() : nullptr;
    std::size_t mo = 0;
    std::uint32_t po = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const std::int32_t c = choice_[i];
        if (c < 0) {
            const Module& m = mods[i];
            Module& d = om[mo];
            d.symbol = m.symbol;
            d.param_count = m.param_count;
            d.first_param = po;
            if (m.param_count != 0) {
                std::memcpy(op + po, ip + m.first_param, m.param_count * sizeof(double));
                po += m.param_count;
            }
            if (lo != nullptr) lo[mo] = 0;
            ++mo;
            continue;
        }
        const Production& p = prods[c];
        if (p.constant_successor) {
            const std::size_t bn = p.block.size();
            const Module* b = p.block.data();
            for (std::size_t k = 0; k < bn; ++k) {
                om[mo + k] = b[k];
                om[mo + k].first_param += po;
            }
            if (!p.block_params.empty()) {
                std::memcpy(op + po, p.block_params.data(), p.block_params.size() * sizeof(double));
                po += static_cast<std::uint32_t>(p.block_params.size());
            }
            if (lo != nullptr) std::memset(lo + mo, 1, bn);
            mo += bn;
            continue;
        }
        std::uint32_t* pos = pos_.data();
        if (p.is_context_sensitive()) match_context(p, i, pos); // matched in pass 1: the same positions
        double* vars = vars_.data();
        bind(p, i, pos, vars);
        ctx_.vars = vars;
        ctx_.position = i;
        ctx_.draws = 1u << 20; // the successor's draws, apart from the condition's
        for (const detail::SuccessorModule& s : p.successor) {
            Module& d = om[mo];
            d.symbol = s.symbol;
            d.param_count = s.param_count;
            d.first_param = po;
            for (std::uint32_t k = 0; k < s.param_count; ++k) {
                double v = 0.0;
                const EvalError err = detail::evaluate(sys_.code, p.param_exprs[s.first_expr + k], ctx_, v);
                if (err != EvalError::None) fail_eval(err, p, i, "successor");
                if (!std::isfinite(v))
                    throw InvalidInput(sys_.source_name + ": step " + std::to_string(step) + ": parameter " +
                                       std::to_string(k + 1) + " of " + sys_.symbol_names[s.symbol] + " in the successor of the production at " +
                                       p.where + " is " + number_text(v) + ", not a finite number, rewriting module " +
                                       std::to_string(i + 1) + " " + module_text(sys_, in, i));
                op[po++] = v;
            }
            if (lo != nullptr) lo[mo] = 1;
            ++mo;
        }
    }
    return rewritten;
}

/// Removes, after every `%` module, the rest of its branch (up to the `]` that closes it, kept)
/// and the `%` itself.
void apply_cut(const LSystem::Impl& sys, Word& w)
{
    const SymbolId cut = sys.cut;
    if (cut == kNoSymbol) return;
    const std::size_t n = w.modules.size();
    std::size_t first = n;
    for (std::size_t i = 0; i < n; ++i)
        if (w.modules[i].symbol == cut) {
            first = i;
            break;
        }
    if (first == n) return;
    const SymbolId lb = sys.left_bracket;
    const SymbolId rb = sys.right_bracket;
    std::size_t mo = first;
    std::uint32_t po = w.modules[first].first_param;
    for (std::size_t i = first; i < n;) {
        const Module m = w.modules[i];
        if (m.symbol == cut) {
            // Skip to the bracket closing this branch (or the end of the word).
            long depth = 0;
            ++i;
            while (i < n) {
                const SymbolId s = w.modules[i].symbol;
                if (s == lb && lb != kNoSymbol) ++depth;
                else if (s == rb && rb != kNoSymbol && depth-- == 0) break;
                ++i;
            }
            continue;
        }
        Module& d = w.modules[mo++];
        d.symbol = m.symbol;
        d.param_count = m.param_count;
        if (m.param_count != 0 && m.first_param != po)
            std::memmove(w.params.data() + po, w.params.data() + m.first_param, m.param_count * sizeof(double));
        d.first_param = po;
        po += m.param_count;
        ++i;
    }
    w.modules.resize(mo);
    w.params.resize(po);
}

/// Applies a decomposition or homomorphism set up to its depth (cpfg: productions applied to
/// what they produced, depth-first, up to `maximum depth:` levels; level by level here, which
/// gives the same word since these productions are context-free).
void apply_levels(Rewriter& rw, const ProductionSet& set, Section section, int step, Word& w, std::uint64_t seed)
{
    if (set.empty() || set.depth <= 0) return;
    std::vector<std::uint8_t> live(w.modules.size(), 1);
    std::vector<std::uint8_t> next_live;
    Word next;
    for (int level = 0; level < set.depth; ++level) {
        const std::size_t done = rw.rewrite(set, section, step, level + 1, w, next, &live, &next_live, seed);
        if (done == 0) return;
        std::swap(w, next);
        std::swap(live, next_live);
    }
}

void check_word(const LSystem::Impl& sys, const Word& w, const char* what)
{
    const std::size_t nsym = sys.symbol_names.size();
    for (std::size_t i = 0; i < w.modules.size(); ++i) {
        const Module& m = w.modules[i];
        if (m.symbol >= nsym)
            throw InvalidInput(sys.source_name + ": " + what + ": module " + std::to_string(i + 1) + " has symbol id " +
                               std::to_string(m.symbol) + ", not one of this system's " + std::to_string(nsym));
        if (static_cast<std::size_t>(m.first_param) + m.param_count > w.params.size())
            throw InvalidInput(sys.source_name + ": " + what + ": module " + std::to_string(i + 1) +
                               "'s parameters lie outside the word's parameter values");
    }
}

void step_internal(const LSystem& system, Rewriter& rw, const Word& in, Word& out, int step, const DeriveOptions& options)
{
    const LSystem::Impl& sys = system.impl();
    rw.rewrite(sys.main, kMain, step, 0, in, out, nullptr, nullptr, options.seed);
    apply_levels(rw, sys.decomposition, kDecomposition, step, out, options.seed);
    apply_cut(sys, out);
    if (sys.has_queries && options.answer_queries) options.answer_queries(out);
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Public entry points

Word derive(const LSystem& system, const DeriveOptions& options)
{
    const LSystem::Impl& sys = system.impl();
    const int steps = options.steps < 0 ? sys.derivation_length : options.steps;
    if (steps > kMaxDerivationLength)
        throw InvalidInput(sys.source_name + ": " + std::to_string(steps) + " derivation steps, over the limit of " +
                           std::to_string(kMaxDerivationLength));
    Rewriter rw(sys, options);
    Word word = sys.axiom;
    if (word.modules.size() > rw.max_modules() || word.params.size() > rw.max_params())
        throw InvalidInput(sys.source_name + ": step 0: the axiom is over the word limits");
    if (sys.has_queries && options.answer_queries) options.answer_queries(word);
    Word next;
    for (int step = 1; step <= steps; ++step) {
        step_internal(system, rw, word, next, step, options);
        std::swap(word, next);
    }
    return word;
}

void derive_step(const LSystem& system, const Word& in, Word& out, int step, const DeriveOptions& options)
{
    check_word(system.impl(), in, ("step " + std::to_string(step)).c_str());
    if (&in == &out) {
        const Word copy = in;
        derive_step(system, copy, out, step, options);
        return;
    }
    Rewriter rw(system.impl(), options);
    step_internal(system, rw, in, out, step, options);
}

Word interpretation_word(const LSystem& system, const Word& word, std::uint64_t seed)
{
    DeriveOptions options;
    options.seed = seed;
    return interpretation_word(system, word, options);
}

Word interpretation_word(const LSystem& system, const Word& word, const DeriveOptions& options)
{
    const LSystem::Impl& sys = system.impl();
    if (sys.homomorphism.empty() || sys.homomorphism.depth <= 0) return word;
    check_word(sys, word, "homomorphism");
    Rewriter rw(sys, options);
    Word w = word;
    apply_levels(rw, sys.homomorphism, kHomomorphism, 0, w, options.seed);
    return w;
}

std::string to_string(const LSystem& system, const Word& word)
{
    const LSystem::Impl& sys = system.impl();
    std::string out;
    out.reserve(word.modules.size() * 2 + word.params.size() * 4);
    for (const Module& m : word.modules) {
        if (static_cast<std::size_t>(m.first_param) + m.param_count > word.params.size()) {
            out += "<bad module>";
            continue;
        }
        append_module(out, sys, word, m);
    }
    return out;
}

} // namespace lobe::lsystem
