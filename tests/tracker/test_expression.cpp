// The expression language of analytic fields (tracker/flows/expression.h): values, precedence,
// errors with their columns, and the nesting limit.
#include "tracker/flows/expression.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace meniscus::tracker {
namespace {

const std::vector<std::string> XYZT = {"x", "y", "z", "t"};

/// The value of `text` at x = 2, y = 3, z = 5, t = 0.5.
double value(const std::string& text,
             const std::vector<std::pair<std::string, double>>& constants = {}) {
    const double values[4] = {2.0, 3.0, 5.0, 0.5};
    return Expression(text, XYZT, constants).evaluate(values);
}

/// The ExpressionError `text` raises (fails the test if it parses).
ExpressionError error_of(const std::string& text) {
    try {
        Expression(text, XYZT);
    } catch (const ExpressionError& e) {
        return e;
    }
    ADD_FAILURE() << "'" << text << "' parsed";
    return ExpressionError(0, "");
}

TEST(Expression, NumbersVariablesAndConstants) {
    EXPECT_EQ(value("42"), 42.0);
    EXPECT_EQ(value("0.5"), 0.5);
    EXPECT_EQ(value(".25"), 0.25);
    EXPECT_EQ(value("1e-3"), 1e-3);
    EXPECT_EQ(value("2.5E+2"), 250.0);
    EXPECT_EQ(value("x"), 2.0);
    EXPECT_EQ(value("y"), 3.0);
    EXPECT_EQ(value("z"), 5.0);
    EXPECT_EQ(value("t"), 0.5);
    EXPECT_EQ(value("pi"), M_PI);
    EXPECT_EQ(value("omega * x", {{"omega", 4.0}}), 8.0);
    EXPECT_EQ(value(" \t x  +  y "), 5.0);
}

TEST(Expression, PrecedenceAndAssociativity) {
    EXPECT_EQ(value("1 + 2 * 3"), 7.0);
    EXPECT_EQ(value("(1 + 2) * 3"), 9.0);
    EXPECT_EQ(value("8 / 4 / 2"), 1.0);    // left-associative
    EXPECT_EQ(value("8 - 4 - 2"), 2.0);    // left-associative
    EXPECT_EQ(value("2 ^ 3 ^ 2"), 512.0);  // right-associative: 2^9
    EXPECT_EQ(value("-x ^ 2"), -4.0);      // −(x²)
    EXPECT_EQ(value("(-x) ^ 2"), 4.0);
    EXPECT_EQ(value("2 ^ -1"), 0.5);
    EXPECT_EQ(value("2 * -3"), -6.0);
    EXPECT_EQ(value("--x"), 2.0);
    EXPECT_EQ(value("+x"), 2.0);
    EXPECT_EQ(value("x * y ^ 2"), 18.0);
    EXPECT_EQ(value("-(y - 0.5) * 2 * pi"), -2.5 * 2.0 * M_PI);
}

TEST(Expression, Functions) {
    EXPECT_DOUBLE_EQ(value("sin(pi / 2)"), 1.0);
    EXPECT_DOUBLE_EQ(value("cos(0)"), 1.0);
    EXPECT_DOUBLE_EQ(value("tan(atan(y))"), 3.0);
    EXPECT_DOUBLE_EQ(value("asin(1)"), M_PI / 2);
    EXPECT_DOUBLE_EQ(value("acos(1)"), 0.0);
    EXPECT_DOUBLE_EQ(value("sinh(0) + cosh(0) + tanh(0)"), 1.0);
    EXPECT_DOUBLE_EQ(value("exp(log(z))"), 5.0);
    EXPECT_DOUBLE_EQ(value("log10(1000)"), 3.0);
    EXPECT_DOUBLE_EQ(value("sqrt(x * 8)"), 4.0);
    EXPECT_EQ(value("abs(-x)"), 2.0);
    EXPECT_EQ(value("floor(-0.5)"), -1.0);
    EXPECT_EQ(value("ceil(t)"), 1.0);
    EXPECT_EQ(value("sign(-3) + sign(0) + sign(y)"), 0.0);
    EXPECT_DOUBLE_EQ(value("atan2(1, 1)"), M_PI / 4);
    EXPECT_EQ(value("pow(x, 10)"), 1024.0);
    EXPECT_EQ(value("mod(7, y)"), 1.0);
    EXPECT_EQ(value("mod(-7, y)"), -1.0);  // the sign of the first argument (std::fmod)
    EXPECT_EQ(value("min(x, y)"), 2.0);
    EXPECT_EQ(value("max(x, y, z, 1)"), 5.0);
    EXPECT_EQ(value("min(z, y, x)"), 2.0);
    EXPECT_EQ(value("max(min(x, y), -z)"), 2.0);
}

TEST(Expression, IeeeResultsAreNotParseErrors) {
    EXPECT_TRUE(std::isnan(value("log(-1)")));
    EXPECT_TRUE(std::isinf(value("1 / 0")));
}

TEST(Expression, ErrorsNameTheColumnOfTheBadToken) {
    struct Case {
        const char* text;
        int column;
        const char* says;
    };
    const Case cases[] = {
        {"", 1, "empty expression"},
        {"   ", 4, "empty expression"},
        {"x + * y", 5, "unexpected '*'"},
        {"x +", 4, "ends where a number"},
        {"(x + 1", 7, "missing ')' for the '(' at column 1"},
        {"x + 1)", 6, "unexpected ')'"},
        {"2 x", 3, "expected an operator"},
        {"x + q", 5, "unknown name 'q'"},
        {"sin x", 1, "sin is a function: write sin(...)"},
        {"sin + 1", 1, "sin is a function"},
        {"foo(x)", 1, "unknown function 'foo'"},
        {"atan2(y)", 1, "atan2 takes 2 arguments, got 1"},
        {"sin(x, y)", 1, "sin takes 1 argument, got 2"},
        {"max(x)", 1, "max takes 2 or more arguments, got 1"},
        {"min(x, y", 9, "missing ')' for the call of min at column 1"},
        {"x $ y", 3, "unexpected character '$'"},
        {"1e+", 1, "malformed number '1e+'"},
        {"1e999", 1, "out of range"},
        {"x,y", 2, "unexpected ','"},
        {"π * x", 1, "unexpected character 'π'"},
        {"y + π", 5, "unexpected character 'π'"},  // columns count characters, not bytes
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(std::string("'") + c.text + "'");
        const ExpressionError e = error_of(c.text);
        EXPECT_EQ(e.column(), c.column) << e.what();
        EXPECT_NE(e.problem().find(c.says), std::string::npos) << e.what();
        EXPECT_EQ(std::string(e.what()).rfind("column " + std::to_string(c.column) + ": ", 0), 0u)
            << e.what();
    }
    // An unknown name lists what is known.
    const std::string what = error_of("x + q").what();
    EXPECT_NE(what.find("names: x, y, z, t, pi"), std::string::npos) << what;
    EXPECT_NE(what.find("sin"), std::string::npos) << what;
}

TEST(Expression, NestingDeeperThanTheLimitIsAnErrorNotAStackOverflow) {
    const int limit = Expression::MAX_DEPTH;
    // Parentheses: each pair opens a level beside the unary it sits in; find the deepest that
    // parses, then check one more fails with the depth message.
    const auto nested = [](int n) {
        return std::string(static_cast<size_t>(n), '(') + "x" +
               std::string(static_cast<size_t>(n), ')');
    };
    int deepest = 0;
    for (int n = 1; n <= limit; ++n) {
        try {
            Expression(nested(n), XYZT);
            deepest = n;
        } catch (const ExpressionError&) {
            break;
        }
    }
    EXPECT_GE(deepest, limit / 2 - 1);  // about limit/2 pairs: each pair is two levels
    const double values[4] = {2.0, 3.0, 5.0, 0.5};
    EXPECT_EQ(Expression(nested(deepest), XYZT).evaluate(values), 2.0);
    const ExpressionError e = error_of(nested(deepest + 1));
    EXPECT_NE(e.problem().find("nested deeper than " + std::to_string(limit)), std::string::npos)
        << e.what();
    // Far deeper texts of every nesting kind fail the same way (the parser stops at the limit).
    std::string calls, powers = "x";
    for (int i = 0; i < 1000; ++i) {
        calls += "sin(";
        powers += "^x";
    }
    calls += "x" + std::string(1000, ')');
    for (const std::string& deep : {nested(4000), std::string(5000, '-') + "x", calls, powers}) {
        ASSERT_LE(deep.size(), Expression::MAX_LENGTH);
        const ExpressionError d = error_of(deep);
        EXPECT_NE(d.problem().find("nested deeper"), std::string::npos) << d.problem();
    }
    // Texts longer than MAX_LENGTH are refused before parsing.
    const ExpressionError too_long = error_of(nested(100000));
    EXPECT_NE(too_long.problem().find("longer than"), std::string::npos) << too_long.problem();
    // Long but flat texts are fine: a sum of 2000 terms keeps two values on the stack.
    std::string sum = "x";
    for (int i = 0; i < 2000; ++i)
        sum += "+x";
    EXPECT_EQ(Expression(sum, XYZT).evaluate(values), 2.0 * 2001);
}

TEST(Expression, BadVariableAndConstantNamesAreRejected) {
    EXPECT_THROW(Expression("1", {"x", "x"}), std::invalid_argument);
    EXPECT_THROW(Expression("1", {"2x"}), std::invalid_argument);
    EXPECT_THROW(Expression("1", {"pi"}), std::invalid_argument);
    EXPECT_THROW(Expression("1", {"sin"}), std::invalid_argument);
    EXPECT_THROW(Expression("1", {"x"}, {{"x", 1.0}}), std::invalid_argument);
    EXPECT_THROW(Expression("1", {"x"}, {{"k", NAN}}), std::invalid_argument);
    EXPECT_NO_THROW(Expression("k_2 * x", {"x"}, {{"k_2", 1.0}}));
}

}  // namespace
}  // namespace meniscus::tracker
