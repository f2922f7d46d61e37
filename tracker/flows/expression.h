#pragma once
/// \file A small, safe expression language for analytic fields given as text (a scene's
/// velocity field, /flow/expression): numbers, named variables and constants, + − * / ^,
/// parentheses and a fixed set of functions. Parsed once into postfix code, evaluated without
/// recursion or allocation; nothing in the text can run anything but arithmetic.
///
/// Grammar (whitespace between tokens is ignored):
///
///     sum     = product { ("+" | "-") product }
///     product = unary { ("*" | "/") unary }
///     unary   = ("-" | "+") unary | power
///     power   = primary [ "^" unary ]            (right-associative: 2^3^2 = 2^9)
///     primary = number | name | name "(" sum { "," sum } ")" | "(" sum ")"
///
/// so −x^2 = −(x²), 2^−1 = 0.5 and a/b/c = (a/b)/c. Numbers: 1, 0.5, .5, 1e-3, 2.5E+2
/// (read with std::from_chars, independent of the locale). Names: the variables and constants
/// the caller gives, `pi`, and the functions
///
///     one argument:  sin cos tan asin acos atan sinh cosh tanh exp log (natural) log10 sqrt
///                    abs floor ceil sign (−1, 0 or 1)
///     two arguments: atan2(y, x)  pow(a, b)  mod(a, b) (std::fmod: the sign of a)
///     two or more:   min max
///
/// Evaluation follows IEEE arithmetic: log(−1) and 1/0 give NaN and ∞ without an error; a
/// caller that needs finite values checks them (ExpressionField does).

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace meniscus::tracker {

/// A parse error: what is wrong, and where. what() reads "column C: <problem>" with C the
/// 1-based column (in characters of the text) of the offending token, or one past the end
/// for a text that ends too soon.
class ExpressionError : public std::invalid_argument {
public:
    ExpressionError(int column, const std::string& problem);
    int column() const { return m_column; }
    const std::string& problem() const { return m_problem; }

private:
    int m_column;
    std::string m_problem;
};

/// A compiled expression over named variables.
class Expression {
public:
    /// Deepest nesting accepted: parentheses, function arguments, unary signs and exponents
    /// each open a level. Deeper texts are an ExpressionError (the parser recurses once per
    /// level, so this bounds its stack use).
    static constexpr int MAX_DEPTH = 64;
    /// Longest text accepted (characters).
    static constexpr size_t MAX_LENGTH = 10000;

    /// Parses `text`. `variables` are the names whose values evaluate() receives, in that order;
    /// `constants` are further names with fixed values. Names are letters, digits and '_', not
    /// starting with a digit; none may repeat or be a function name, and `pi` is built in.
    /// Throws ExpressionError for a text that does not parse, std::invalid_argument for bad
    /// names.
    Expression(const std::string& text, const std::vector<std::string>& variables,
               const std::vector<std::pair<std::string, double>>& constants = {});

    /// The value for `values[i]` of variable i (as many as the constructor's `variables`).
    double evaluate(const double* values) const;

    const std::string& text() const { return m_text; }

    /// Every function name, for error messages and references: "sin, cos, …".
    static std::string function_names();

    /// One postfix instruction (public for the compiler in expression.cpp).
    struct Instruction {
        enum class Op {
            constant,
            variable,
            negate,
            add,
            subtract,
            multiply,
            divide,
            power,
            call1,
            call2
        };
        Op op = Op::constant;
        double value = 0.0;  ///< constant
        int index = 0;       ///< variable
        double (*f1)(double) = nullptr;
        double (*f2)(double, double) = nullptr;
    };

private:
    /// Operand stack evaluate() keeps on the call stack; MAX_DEPTH bounds what a text needs.
    static constexpr int STACK_CAPACITY = 4 * MAX_DEPTH + 8;

    std::string m_text;
    int m_variables = 0;
    std::vector<Instruction> m_code;
};

}  // namespace meniscus::tracker
