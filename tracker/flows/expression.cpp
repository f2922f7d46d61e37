#include "tracker/flows/expression.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <set>

namespace meniscus::tracker {

namespace {

using Instruction = Expression::Instruction;
using Op = Instruction::Op;

double sign(double v) {
    return static_cast<double>((v > 0.0) - (v < 0.0));
}
double min2(double a, double b) {
    return std::min(a, b);
}
double max2(double a, double b) {
    return std::max(a, b);
}

struct Function1 {
    const char* name;
    double (*f)(double);
};
struct Function2 {
    const char* name;
    double (*f)(double, double);
    bool variadic;  ///< two or more arguments, folded left
};

// Casts pick the double overloads of <cmath>.
const std::array<Function1, 17> FUNCTIONS_1 = {{
    {"sin", static_cast<double (*)(double)>(std::sin)},
    {"cos", static_cast<double (*)(double)>(std::cos)},
    {"tan", static_cast<double (*)(double)>(std::tan)},
    {"asin", static_cast<double (*)(double)>(std::asin)},
    {"acos", static_cast<double (*)(double)>(std::acos)},
    {"atan", static_cast<double (*)(double)>(std::atan)},
    {"sinh", static_cast<double (*)(double)>(std::sinh)},
    {"cosh", static_cast<double (*)(double)>(std::cosh)},
    {"tanh", static_cast<double (*)(double)>(std::tanh)},
    {"exp", static_cast<double (*)(double)>(std::exp)},
    {"log", static_cast<double (*)(double)>(std::log)},
    {"log10", static_cast<double (*)(double)>(std::log10)},
    {"sqrt", static_cast<double (*)(double)>(std::sqrt)},
    {"abs", static_cast<double (*)(double)>(std::fabs)},
    {"floor", static_cast<double (*)(double)>(std::floor)},
    {"ceil", static_cast<double (*)(double)>(std::ceil)},
    {"sign", sign},
}};
const std::array<Function2, 5> FUNCTIONS_2 = {{
    {"atan2", static_cast<double (*)(double, double)>(std::atan2), false},
    {"pow", static_cast<double (*)(double, double)>(std::pow), false},
    {"mod", static_cast<double (*)(double, double)>(std::fmod), false},
    {"min", min2, true},
    {"max", max2, true},
}};

const Function1* find_function_1(const std::string& name) {
    for (const Function1& f : FUNCTIONS_1)
        if (name == f.name)
            return &f;
    return nullptr;
}
const Function2* find_function_2(const std::string& name) {
    for (const Function2& f : FUNCTIONS_2)
        if (name == f.name)
            return &f;
    return nullptr;
}

bool is_name_start(char c) {
    return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}
bool is_name_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

bool valid_name(const std::string& name) {
    return !name.empty() && is_name_start(name.front()) &&
           std::all_of(name.begin(), name.end(), is_name_char);
}

struct Token {
    enum class Kind { number, name, symbol, end };
    Kind kind = Kind::end;
    size_t offset = 0;  ///< byte offset in the text
    std::string text;   ///< name or symbol; the number's characters
    double number = 0.0;
};

/// Recursive-descent compiler from text to postfix code (see the grammar in expression.h).
class Compiler {
public:
    Compiler(const std::string& text, const std::vector<std::string>& variables,
             const std::vector<std::pair<std::string, double>>& constants)
        : m_text(text), m_variables(variables), m_constants(constants) {
        advance();
    }

    std::vector<Instruction> compile() {
        if (m_token.kind == Token::Kind::end)
            fail(m_token, "empty expression");
        parse_sum();
        if (m_token.kind != Token::Kind::end)
            fail(m_token, "unexpected " + describe(m_token) +
                              ": expected an operator (+ - * / ^) or the end");
        return std::move(m_code);
    }

    int max_stack() const { return m_max_stack; }

private:
    /// 1-based column of a byte offset, counting UTF-8 characters.
    int column(size_t offset) const {
        int c = 1;
        for (size_t i = 0; i < offset && i < m_text.size(); ++i)
            if ((static_cast<unsigned char>(m_text[i]) & 0xC0) != 0x80)
                ++c;
        return c;
    }

    [[noreturn]] void fail(const Token& at, const std::string& problem) const {
        throw ExpressionError(column(at.offset), problem);
    }

    static std::string describe(const Token& t) {
        switch (t.kind) {
            case Token::Kind::number:
                return "number '" + t.text + "'";
            case Token::Kind::name:
                return "name '" + t.text + "'";
            case Token::Kind::symbol:
                return "'" + t.text + "'";
            case Token::Kind::end:
                break;
        }
        return "end of the expression";
    }

    void advance() {
        size_t i = m_pos;
        while (i < m_text.size() && (m_text[i] == ' ' || m_text[i] == '\t'))
            ++i;
        Token t;
        t.offset = i;
        if (i >= m_text.size()) {
            t.kind = Token::Kind::end;
            m_pos = i;
            m_token = t;
            return;
        }
        const char c = m_text[i];
        if (std::isdigit(static_cast<unsigned char>(c)) ||
            (c == '.' && i + 1 < m_text.size() &&
             std::isdigit(static_cast<unsigned char>(m_text[i + 1])))) {
            size_t j = i;
            const auto digits = [&] {
                while (j < m_text.size() && std::isdigit(static_cast<unsigned char>(m_text[j])))
                    ++j;
            };
            digits();
            if (j < m_text.size() && m_text[j] == '.') {
                ++j;
                digits();
            }
            if (j < m_text.size() && (m_text[j] == 'e' || m_text[j] == 'E')) {
                size_t k = j + 1;
                if (k < m_text.size() && (m_text[k] == '+' || m_text[k] == '-'))
                    ++k;
                if (k >= m_text.size() || !std::isdigit(static_cast<unsigned char>(m_text[k]))) {
                    t.text = m_text.substr(i, k - i);
                    fail(t, "malformed number '" + t.text + "': the exponent needs digits");
                }
                j = k;
                digits();
            }
            t.kind = Token::Kind::number;
            t.text = m_text.substr(i, j - i);
            const auto r = std::from_chars(m_text.data() + i, m_text.data() + j, t.number);
            if (r.ec != std::errc() || r.ptr != m_text.data() + j || !std::isfinite(t.number))
                fail(t, "number '" + t.text + "' is out of range");
            m_pos = j;
        } else if (is_name_start(c)) {
            size_t j = i;
            while (j < m_text.size() && is_name_char(m_text[j]))
                ++j;
            t.kind = Token::Kind::name;
            t.text = m_text.substr(i, j - i);
            m_pos = j;
        } else if (std::string("+-*/^(),").find(c) != std::string::npos) {
            t.kind = Token::Kind::symbol;
            t.text = std::string(1, c);
            m_pos = i + 1;
        } else {
            // One whole UTF-8 character in the message.
            size_t j = i + 1;
            while (j < m_text.size() && (static_cast<unsigned char>(m_text[j]) & 0xC0) == 0x80)
                ++j;
            t.kind = Token::Kind::symbol;
            t.text = m_text.substr(i, j - i);
            fail(t, "unexpected character '" + t.text +
                        "' (expressions use numbers, names, + - * / ^, parentheses and commas)");
        }
        m_token = t;
    }

    bool at_symbol(char c) const {
        return m_token.kind == Token::Kind::symbol && m_token.text.size() == 1 &&
               m_token.text[0] == c;
    }

    /// Opens a nesting level for the duration of a scope; throws past MAX_DEPTH.
    class Level {
    public:
        Level(Compiler& c, const Token& at) : m_c(c) {
            if (++m_c.m_depth > Expression::MAX_DEPTH)
                m_c.fail(at, "nested deeper than " + std::to_string(Expression::MAX_DEPTH) +
                                 " levels (parentheses, function calls, signs, exponents)");
        }
        ~Level() { --m_c.m_depth; }
        Level(const Level&) = delete;
        Level& operator=(const Level&) = delete;

    private:
        Compiler& m_c;
    };

    void emit(Instruction in, int stack_change) {
        m_code.push_back(in);
        m_stack += stack_change;
        m_max_stack = std::max(m_max_stack, m_stack);
    }
    void emit_op(Op op, int stack_change) {
        Instruction in;
        in.op = op;
        emit(in, stack_change);
    }

    void parse_sum() {
        parse_product();
        while (at_symbol('+') || at_symbol('-')) {
            const Op op = at_symbol('+') ? Op::add : Op::subtract;
            advance();
            parse_product();
            emit_op(op, -1);
        }
    }

    void parse_product() {
        parse_unary();
        while (at_symbol('*') || at_symbol('/')) {
            const Op op = at_symbol('*') ? Op::multiply : Op::divide;
            advance();
            parse_unary();
            emit_op(op, -1);
        }
    }

    void parse_unary() {
        const Level level(*this, m_token);
        if (at_symbol('-') || at_symbol('+')) {
            const bool negate = at_symbol('-');
            advance();
            parse_unary();
            if (negate)
                emit_op(Op::negate, 0);
            return;
        }
        parse_primary();
        if (at_symbol('^')) {
            advance();
            parse_unary();  // right-associative, and 2^-1 reads as 2^(-1)
            emit_op(Op::power, -1);
        }
    }

    void expect_operand_start(const Token& t) const {
        if (t.kind == Token::Kind::end)
            fail(t, "the expression ends where a number, name or '(' is expected");
        if (t.kind == Token::Kind::symbol && t.text != "(")
            fail(t, "unexpected " + describe(t) + ": expected a number, name or '('");
    }

    void parse_primary() {
        const Token t = m_token;
        expect_operand_start(t);
        if (t.kind == Token::Kind::number) {
            Instruction in;
            in.op = Op::constant;
            in.value = t.number;
            emit(in, 1);
            advance();
            return;
        }
        if (at_symbol('(')) {
            advance();
            {
                const Level level(*this, t);
                parse_sum();
            }
            if (!at_symbol(')'))
                fail(m_token, "missing ')' for the '(' at column " +
                                  std::to_string(column(t.offset)) + " (found " +
                                  describe(m_token) + ")");
            advance();
            return;
        }
        // A name.
        advance();
        if (at_symbol('('))
            return parse_call(t);
        for (size_t i = 0; i < m_variables.size(); ++i)
            if (m_variables[i] == t.text) {
                Instruction in;
                in.op = Op::variable;
                in.index = static_cast<int>(i);
                emit(in, 1);
                return;
            }
        for (const auto& [name, value] : m_constants)
            if (name == t.text) {
                Instruction in;
                in.op = Op::constant;
                in.value = value;
                emit(in, 1);
                return;
            }
        if (t.text == "pi") {
            Instruction in;
            in.op = Op::constant;
            in.value = M_PI;
            emit(in, 1);
            return;
        }
        if (find_function_1(t.text) || find_function_2(t.text))
            fail(t, t.text + " is a function: write " + t.text + "(...)");
        std::string known;
        for (const std::string& v : m_variables)
            known += (known.empty() ? "" : ", ") + v;
        for (const auto& c : m_constants)
            known += (known.empty() ? "" : ", ") + c.first;
        known += (known.empty() ? "" : ", ") + std::string("pi");
        fail(t, "unknown name '" + t.text + "' (names: " + known +
                    "; functions: " + Expression::function_names() + ")");
    }

    /// name "(" sum { "," sum } ")", at the '('.
    void parse_call(const Token& name) {
        const Function1* f1 = find_function_1(name.text);
        const Function2* f2 = find_function_2(name.text);
        if (!f1 && !f2)
            fail(name, "unknown function '" + name.text +
                           "' (functions: " + Expression::function_names() + ")");
        const Token open = m_token;
        advance();
        int arguments = 0;
        {
            const Level level(*this, open);
            for (;;) {
                parse_sum();
                ++arguments;
                if (f2 && f2->variadic && arguments >= 2) {
                    Instruction in;
                    in.op = Op::call2;
                    in.f2 = f2->f;
                    emit(in, -1);
                }
                if (!at_symbol(','))
                    break;
                advance();
            }
        }
        if (!at_symbol(')'))
            fail(m_token, "missing ')' for the call of " + name.text + " at column " +
                              std::to_string(column(name.offset)) + " (found " + describe(m_token) +
                              ")");
        const int wanted = f1 ? 1 : 2;
        const bool variadic = f2 && f2->variadic;
        if (variadic ? arguments < 2 : arguments != wanted)
            fail(name, name.text + " takes " + (variadic ? "2 or more" : std::to_string(wanted)) +
                           " argument" + (wanted == 1 && !variadic ? "" : "s") + ", got " +
                           std::to_string(arguments));
        advance();
        if (variadic)
            return;  // folded above
        Instruction in;
        if (f1) {
            in.op = Op::call1;
            in.f1 = f1->f;
            emit(in, 0);
        } else {
            in.op = Op::call2;
            in.f2 = f2->f;
            emit(in, -1);
        }
    }

    const std::string& m_text;
    const std::vector<std::string>& m_variables;
    const std::vector<std::pair<std::string, double>>& m_constants;
    size_t m_pos = 0;
    Token m_token;
    int m_depth = 0;
    int m_stack = 0, m_max_stack = 0;
    std::vector<Instruction> m_code;
};

}  // namespace

ExpressionError::ExpressionError(int column, const std::string& problem)
    : std::invalid_argument("column " + std::to_string(column) + ": " + problem),
      m_column(column),
      m_problem(problem) {}

std::string Expression::function_names() {
    std::string names;
    for (const Function1& f : FUNCTIONS_1)
        names += (names.empty() ? "" : ", ") + std::string(f.name);
    for (const Function2& f : FUNCTIONS_2)
        names += ", " + std::string(f.name);
    return names;
}

Expression::Expression(const std::string& text, const std::vector<std::string>& variables,
                       const std::vector<std::pair<std::string, double>>& constants)
    : m_text(text), m_variables(static_cast<int>(variables.size())) {
    std::set<std::string> names;
    const auto check_name = [&](const std::string& name, const char* what) {
        if (!valid_name(name))
            throw std::invalid_argument(std::string(what) + " '" + name +
                                        "': expected letters, digits and '_', not starting "
                                        "with a digit");
        if (name == "pi" || find_function_1(name) || find_function_2(name))
            throw std::invalid_argument(std::string(what) + " '" + name +
                                        "': a built-in name (pi or a function)");
        if (!names.insert(name).second)
            throw std::invalid_argument(std::string(what) + " '" + name +
                                        "': already a variable or another constant");
    };
    for (const std::string& v : variables)
        check_name(v, "variable");
    for (const auto& [name, value] : constants) {
        check_name(name, "constant");
        if (!std::isfinite(value))
            throw std::invalid_argument("constant '" + name + "': expected a finite number");
    }
    if (text.size() > MAX_LENGTH)
        throw ExpressionError(static_cast<int>(MAX_LENGTH) + 1,
                              "longer than " + std::to_string(MAX_LENGTH) + " characters");
    Compiler compiler(m_text, variables, constants);
    m_code = compiler.compile();
    if (compiler.max_stack() > STACK_CAPACITY)  // MAX_DEPTH keeps texts far below this
        throw ExpressionError(1, "too complex: needs " + std::to_string(compiler.max_stack()) +
                                     " intermediate values (at most " +
                                     std::to_string(STACK_CAPACITY) + ")");
}

double Expression::evaluate(const double* values) const {
    std::array<double, STACK_CAPACITY> stack;
    int top = -1;  // index of the top value
    for (const Instruction& in : m_code) {
        switch (in.op) {
            case Op::constant:
                stack[static_cast<size_t>(++top)] = in.value;
                break;
            case Op::variable:
                stack[static_cast<size_t>(++top)] = values[in.index];
                break;
            case Op::negate:
                stack[static_cast<size_t>(top)] = -stack[static_cast<size_t>(top)];
                break;
            case Op::call1:
                stack[static_cast<size_t>(top)] = in.f1(stack[static_cast<size_t>(top)]);
                break;
            default: {  // binary: a (below) op b (top)
                const double b = stack[static_cast<size_t>(top--)];
                double& a = stack[static_cast<size_t>(top)];
                switch (in.op) {
                    case Op::add:
                        a += b;
                        break;
                    case Op::subtract:
                        a -= b;
                        break;
                    case Op::multiply:
                        a *= b;
                        break;
                    case Op::divide:
                        a /= b;
                        break;
                    case Op::power:
                        a = std::pow(a, b);
                        break;
                    default:  // call2
                        a = in.f2(a, b);
                        break;
                }
            }
        }
    }
    return stack[0];
}

}  // namespace meniscus::tracker
