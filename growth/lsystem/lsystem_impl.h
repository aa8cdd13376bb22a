#pragma once
/// \file lsystem_impl.h
/// The compiled form of an L-system (LSystem::Impl): interned symbols, productions indexed by
/// predecessor symbol, successors pre-built where they are constant, expressions as bytecode
/// (expr.h). Private to growth/lsystem/.

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "growth/lsystem/expr.h"
#include "growth/lsystem/lsystem.h"

namespace lobe::lsystem {

inline constexpr SymbolId kNoSymbol = 0xFFFF;
/// Most distinct symbols one system may use.
inline constexpr std::size_t kMaxSymbols = 0xFFF0;
/// Most formal parameters one production binds (predecessor and contexts together).
inline constexpr std::size_t kMaxProductionVars = 1024;
/// Largest `maximum depth:` of a decomposition or homomorphism.
inline constexpr int kMaxSectionDepth = 100;

namespace detail {

/// A module of a predecessor or context: its symbol, how many parameters it must carry, and
/// the variable slot of its first formal parameter.
struct PatternModule {
    SymbolId symbol = 0;
    std::uint16_t param_count = 0;
    std::uint32_t first_var = 0;
};

/// A module of a successor: parameters are expressions (indices into Production::param_exprs).
struct SuccessorModule {
    SymbolId symbol = 0;
    std::uint16_t param_count = 0;
    std::uint32_t first_expr = 0;
};

struct Production {
    PatternModule pred;
    std::vector<PatternModule> left;  ///< left context, in reading order
    std::vector<PatternModule> right; ///< right context, in reading order (may hold `[` `]`)
    std::uint32_t var_count = 0;
    bool has_condition = false;
    Expr condition;
    bool has_probability = false;
    Expr probability;
    std::vector<SuccessorModule> successor;
    std::vector<Expr> param_exprs;
    /// All successor parameters constant: the successor is `block` with `block_params`
    /// (block[i].first_param relative to block_params).
    bool constant_successor = true;
    std::vector<Module> block;
    std::vector<double> block_params;
    std::uint32_t successor_param_count = 0;
    std::uint64_t successor_cost = 0; ///< instructions of its non-constant parameter expressions
    std::size_t offset = 0; ///< where the production starts in the source (messages)
    std::string where;      ///< "NAME:LINE:COL" of the production
    bool is_context_sensitive() const { return !left.empty() || !right.empty(); }
};

/// How a symbol is rewritten by one production set.
struct SymbolRule {
    enum Kind : std::uint8_t { None, ConstantBlock, General };
    Kind kind = None;
    std::uint16_t pred_params = 0;       ///< ConstantBlock: parameter count it matches
    std::uint32_t production = 0;        ///< ConstantBlock: the production
    std::uint32_t block_modules = 0;     ///< ConstantBlock: modules and parameters it writes
    std::uint32_t block_params = 0;
    std::uint32_t first = 0;             ///< General: candidates in ProductionSet::candidates
    std::uint32_t cs_count = 0;          ///< context-sensitive candidates (tried first)
    std::uint32_t cf_count = 0;          ///< then context-free ones
    bool cs_stochastic = false;          ///< a candidate among the first cs_count has a probability
    bool cf_stochastic = false;
};

struct ProductionSet {
    std::vector<Production> productions;
    std::vector<std::uint32_t> candidates; ///< production indices, grouped per symbol
    std::vector<SymbolRule> rules;         ///< by SymbolId
    int depth = 1;                         ///< `maximum depth:` (decomposition, homomorphism)
    bool has_context = false;
    std::uint32_t max_vars = 0;
    bool empty() const { return productions.empty(); }
};

} // namespace detail

struct LSystem::Impl {
    std::string source_name;
    int derivation_length = 0;
    Word axiom;
    std::vector<std::string> symbol_names;
    std::unordered_map<std::string, SymbolId> symbol_ids;
    std::vector<std::uint8_t> ignored; ///< by SymbolId: skipped when matching context
    SymbolId left_bracket = kNoSymbol;
    SymbolId right_bracket = kNoSymbol;
    SymbolId cut = kNoSymbol;
    bool has_queries = false;
    std::vector<detail::Instr> code;
    detail::ProductionSet main;
    detail::ProductionSet decomposition;
    detail::ProductionSet homomorphism;
};

namespace detail {
/// Builds ProductionSet::candidates and ::rules once the productions are known.
void index_productions(ProductionSet& set, std::size_t symbol_count);
} // namespace detail

} // namespace lobe::lsystem
