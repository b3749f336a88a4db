// Readers and writers of the formats: every malformed input is named by
// file:line:column, nothing malformed passes as data.
#include <gtest/gtest.h>

#include <charconv>
#include <clocale>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/input_error.hpp"
#include "ascorr_text/numbers.hpp"
#include "test_support.hpp"

namespace ascorr::host {
namespace {

const char* kHeader = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";

std::vector<SolutionRecord> parse_all(const std::string& text) {
    SolutionsReader r("f.csv", text);
    std::vector<SolutionRecord> out;
    SolutionRecord rec;
    while (r.next(rec)) {
        out.push_back(rec);
    }
    return out;
}

// Returns "line:column: message" of the error, or "" if none.
std::string error_of(const std::string& text) {
    try {
        parse_all(text);
    } catch (const text::InputError& e) {
        EXPECT_EQ(e.file(), "f.csv");
        return std::to_string(e.line()) + ":" + std::to_string(e.column()) + ": " + e.what();
    }
    return "";
}

// Expects the message of REFUSAL(text) to hold part, for each {text, part}.
template <typename F>
void expect_refusals(F refusal, const std::vector<std::pair<std::string, std::string>>& cases) {
    for (const auto& [text, part] : cases) {
        const std::string e = refusal(text);
        EXPECT_NE(e.find(part), std::string::npos) << text << ": " << e;
    }
}

TEST(SolutionsReader, ReadsExampleFile) {
    std::string text;
    const auto rows = test::read_records(test::data_path("solutions.csv"), text);
    ASSERT_EQ(rows.size(), 12U);
    EXPECT_EQ(rows[0].line, 2U);
    EXPECT_DOUBLE_EQ(rows[0].t, 447534187.831);
    EXPECT_EQ(rows[0].head, 0);
    EXPECT_DOUBLE_EQ(rows[0].q_chu_icrf.x, -0.642227588171342);
    EXPECT_DOUBLE_EQ(rows[0].temperature[2], -19.775);
    EXPECT_EQ(rows[0].velocity_components, 3);
    EXPECT_DOUBLE_EQ(rows[0].v_sc_kms.z, -1.785468);
    EXPECT_EQ(rows[1].head, 1);
    EXPECT_EQ(rows[2].head, 2);
}

TEST(SolutionsReader, MissingValuesAndUnknownColumns) {
    const std::string text =
        "extra,t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz\n"
        "x,1.5,B,1,0,0,0,,nan,NaN,,,\r\n"
        "y,2.5,D,1,0,0,0,1,2,3,1,,3\n";
    const auto rows = parse_all(text);
    ASSERT_EQ(rows.size(), 2U);
    EXPECT_FALSE(rows[0].temperature_present[0]);
    EXPECT_FALSE(rows[0].temperature_present[1]);
    EXPECT_FALSE(rows[0].temperature_present[2]);
    EXPECT_EQ(rows[0].velocity_components, 0);
    EXPECT_EQ(rows[1].head, 3);
    EXPECT_EQ(rows[1].velocity_components, 2);
    EXPECT_EQ(rows[1].flags, 0);
    EXPECT_FALSE(rows[1].confidence_present);
}

// A column that looks like one the reader reads, which the header lacks, is
// refused where it stands (issue 30, class 17: a misspelt T_CHU left every row
// without temperatures, exit 0); unknown columns unlike them are kept.
TEST(SolutionsReader, NearMissColumnsAreRefused) {
    const std::string row = "1,A,1,0,0,0,1,2,3,1,2,3,0,1\n";
    const auto header_with = [](const std::string& from, const std::string& to) {
        std::string h = kHeader;
        return h.replace(h.find(from), from.size(), to);
    };
    EXPECT_EQ(error_of(header_with("t_chu", "T_CHU") + row),
              "1:19: f.csv:1:19: column 'T_CHU' is not a column ascorr reads, but looks like 't_chu', which the "
              "header lacks (column names are case-sensitive, docs/contract.md, section 3): rename it 't_chu', or "
              "give it a name unlike the columns ascorr reads");
    const std::pair<const char*, const char*> misses[] = {
        {"t_chu", "tchu"},
        {"t_029", "t_29"},
        {"t_032", "T_023"},
        {"flags", "flag"},
        {"confidence", "confidance"},
        {"confidence", "Confidence"},
        {"chu", "CHU"},
        {"vx", "VX"},
        {"qw", "Qw"},
    };
    for (const auto& [known, written] : misses) {
        const std::string e = error_of(header_with(known, written) + row);
        EXPECT_NE(e.find(std::string("column '") + written + "' is not a column ascorr reads, but looks like '" +
                         known + "'"),
                  std::string::npos)
            << written << ": " << e;
    }
    // Not near misses: a name of the reader's present beside it, short names
    // one or two edits from a short column, names far from every column.
    for (const char* extra : {"t_028", "x", "id", "qa", "note", "temperature", "chu2"}) {
        EXPECT_EQ(error_of(std::string(kHeader).insert(std::strlen(kHeader) - 1, std::string(",") + extra) +
                           "1,A,1,0,0,0,1,2,3,1,2,3,0,1,v\n"),
                  "")
            << extra;
    }
}

TEST(SolutionsReader, UnknownHeadIsDataNotSyntax) {
    const auto rows = parse_all(std::string(kHeader) + "1,X,1,0,0,0,1,2,3,1,2,3,0,1\n");
    ASSERT_EQ(rows.size(), 1U);
    EXPECT_EQ(rows[0].head, kUnknownHead);  // the core rejects it; the row is kept
}

TEST(SolutionsReader, MalformedInputNamesLineAndColumn) {
    const std::string h = kHeader;
    EXPECT_EQ(error_of(""), "1:1: f.csv:1:1: empty file: expected a header line");
    expect_refusals(error_of, {{"t,chu,qw,qx,qy\n", "required column 'qz' is missing"},
                               {"t,chu,qw,qw,qx,qy,qz\n", "appears twice"}});
    // A number that is not one: line 3, column of the qx field.
    const std::string bad_qx = h + "1,A,1,0,0,0,1,2,3,1,2,3,0,1\n" + "2,A,1,abc,0,0,1,2,3,1,2,3,0,1\n";
    EXPECT_EQ(error_of(bad_qx).substr(0, 5), "3:7: ");
    expect_refusals(error_of, {{bad_qx, "column 'qx': expected a number, got 'abc'"},
                               // Truncated row.
                               {h + "1,A,1,0,0,0,1,2\n", "truncated row"},
                               // Too many fields.
                               {h + "1,A,1,0,0,0,1,2,3,1,2,3,0,1,9\n", "found 15"},
                               // Temperature garbage is an error, not "missing".
                               {h + "1,A,1,0,0,0,hot,2,3,1,2,3,0,1\n", "column 't_chu'"},
                               // Non-finite time.
                               {h + "inf,A,1,0,0,0,1,2,3,1,2,3,0,1\n", "time must be finite"},
                               // Flags must be a non-negative integer.
                               {h + "1,A,1,0,0,0,1,2,3,1,2,3,1.5,1\n", "column 'flags'"},
                               {h + "1,A,1,0,0,0,1,2,3,1,2,3,-1,1\n", "column 'flags'"},
                               // Spaces and quotes are not numbers in this format.
                               {h + "1,A, 1,0,0,0,1,2,3,1,2,3,0,1\n", "column 'qw'"},
                               {h + "1,A,\"1\",0,0,0,1,2,3,1,2,3,0,1\n", "column 'qw'"}});
}

TEST(SolutionsReader, ReaderMovesPastABadRow) {
    const std::string text = std::string(kHeader) +
                             "1,A,1,0,0,0,1,2,3,1,2,3,0,1\n2,A,x,0,0,0,1,2,3,1,2,3,0,1\n3,A,1,0,0,0,1,2,3,1,2,3,0,1\n";
    SolutionsReader r("f.csv", text);
    SolutionRecord rec;
    ASSERT_TRUE(r.next(rec));
    EXPECT_THROW(r.next(rec), text::InputError);
    ASSERT_TRUE(r.next(rec));
    EXPECT_EQ(rec.line, 4U);
    EXPECT_FALSE(r.next(rec));
}

// Blocks are whole lines, in order, with correct line numbers, whatever the
// block size: lines longer than a block, no final line end, CRLF.
TEST(BlockReader, WholeLinesAtAnyBlockSize) {
    const auto dir = test::scratch_dir("blocks");
    std::string text;
    for (int i = 1; i <= 200; ++i) {
        text += "line" + std::to_string(i) + std::string(static_cast<std::size_t>(i % 37), 'x') +
                (i % 3 == 0 ? "\r\n" : "\n");
    }
    text += "last-without-newline";
    const auto path = (dir / "f.txt").string();
    std::ofstream(path, std::ios::binary) << text;
    for (std::size_t block_bytes : {1U, 7U, 64U, 1000U, 1U << 20}) {
        BlockReader r(path, block_bytes);
        std::string joined;
        std::string_view block;
        std::size_t expected_lines_before = 0;
        while (r.next(block)) {
            EXPECT_EQ(r.lines_before(), expected_lines_before) << block_bytes;
            EXPECT_TRUE(block.back() == '\n' || joined.size() + block.size() == text.size()) << block_bytes;
            expected_lines_before += count_line_ends(block);
            joined += block;
        }
        EXPECT_EQ(joined, text) << block_bytes;
    }
    std::ofstream(path, std::ios::binary) << std::string("a\nb\0c\n", 6);
    BlockReader r(path, 1U << 20);
    std::string_view block;
    try {
        r.next(block);
        ADD_FAILURE() << "NUL byte not detected";
    } catch (const text::InputError& e) {
        EXPECT_EQ(e.line(), 2U);
    }
}

TEST(Csv, NumbersAndFormatting) {
    EXPECT_EQ(*parse_double("1e-3"), 1e-3);
    EXPECT_EQ(*parse_double("+2.5"), 2.5);
    EXPECT_TRUE(std::isnan(*parse_double("nan")));
    EXPECT_FALSE(parse_double("1.0x"));
    EXPECT_FALSE(parse_double(""));
    EXPECT_FALSE(parse_double("1e999"));
    char buf[64];
    EXPECT_EQ(std::string(buf, format_fixed(buf, buf + 64, -0.642227588171342, 15)), "-0.642227588171342");
}

// The syntax of a real number (ascorr_text/numbers.hpp): std::from_chars's,
// a leading '+' only where the caller accepts one, and a number beyond
// double's range told apart as too large or too small from its digits.
TEST(Numbers, SyntaxAndRangeAreFromCharsAndTheDigits) {
    using text::classify_real;
    using text::LeadingPlus;
    using text::RealText;
    const struct {
        const char* s;
        RealText plus_refused;
        RealText plus_accepted;
    } cases[] = {
        {"1.5", RealText::kNumber, RealText::kNumber},
        {".5", RealText::kNumber, RealText::kNumber},
        {"5.", RealText::kNumber, RealText::kNumber},
        {"-1e-3", RealText::kNumber, RealText::kNumber},
        {"inf", RealText::kNumber, RealText::kNumber},
        {"-Infinity", RealText::kNumber, RealText::kNumber},
        {"nan", RealText::kNumber, RealText::kNumber},
        {"+2", RealText::kNotANumber, RealText::kNumber},
        {"++2", RealText::kNotANumber, RealText::kNotANumber},
        {"-+2", RealText::kNotANumber, RealText::kNotANumber},
        {"0x1p3", RealText::kNotANumber, RealText::kNotANumber},  // no hexadecimal
        {"1p3", RealText::kNotANumber, RealText::kNotANumber},
        {" 1", RealText::kNotANumber, RealText::kNotANumber},  // no spaces
        {"1 ", RealText::kNotANumber, RealText::kNotANumber},
        {"1,5", RealText::kNotANumber, RealText::kNotANumber},  // a decimal comma is no number
        {"1e", RealText::kNotANumber, RealText::kNotANumber},
        {"", RealText::kNotANumber, RealText::kNotANumber},
        {"1e999", RealText::kOverflow, RealText::kOverflow},
        {"-1.5e999", RealText::kOverflow, RealText::kOverflow},
        {"+1e999", RealText::kNotANumber, RealText::kOverflow},
        {"10000e305", RealText::kOverflow, RealText::kOverflow},
        {"0.0001e313", RealText::kOverflow, RealText::kOverflow},
        {"1e99999999999999999999999", RealText::kOverflow, RealText::kOverflow},
        {"1e-999", RealText::kUnderflow, RealText::kUnderflow},
        {"-0.000001e-318", RealText::kUnderflow, RealText::kUnderflow},
        {"100000000000000000000e-344", RealText::kUnderflow, RealText::kUnderflow},
        {"1e-99999999999999999999999", RealText::kUnderflow, RealText::kUnderflow},
        {"0.000e99999", RealText::kNumber, RealText::kNumber},  // zero is never out of range
        {"1000e305", RealText::kNumber, RealText::kNumber},
    };
    for (const auto& c : cases) {
        double x = 0.0;
        EXPECT_EQ(classify_real(c.s, x, LeadingPlus::kRefused), c.plus_refused) << c.s;
        EXPECT_EQ(classify_real(c.s, x, LeadingPlus::kAccepted), c.plus_accepted) << c.s;
    }
    double x = 0.0;
    ASSERT_EQ(classify_real("1000e305", x, LeadingPlus::kRefused), RealText::kNumber);
    EXPECT_EQ(x, 1e308);
}

// A locale whose decimal point is a comma, as a host program or a Python user
// may set (locale.setlocale(locale.LC_NUMERIC, "de_DE")): de_DE.UTF-8 if the
// system has it, else compiled from the `locales` package's definitions
// (toolchain/debian-packages.txt) into the test's folder. Empty if neither.
std::string comma_decimal_locale() {
    for (const char* name : {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8"}) {
        if (std::setlocale(LC_NUMERIC, name) != nullptr) {
            return name;
        }
    }
    const auto dir = test::scratch_dir("locale");
    const std::string command = "localedef -i de_DE -f UTF-8 " + (dir / "de_DE.UTF-8").string() + " 2>/dev/null";
    if (std::system(command.c_str()) != 0) {
        return {};
    }
    ::setenv("LOCPATH", dir.c_str(), 1);  // glibc reads it at each setlocale
    return std::setlocale(LC_NUMERIC, "de_DE.UTF-8") != nullptr ? "de_DE.UTF-8" : "";
}

// Under a comma-decimal C locale every number still reads with a point: a
// number beyond double's range is still too large (strtod, which the range
// was once told with, reads "1.5e999" as 1 there: too small).
TEST(Numbers, ReadAlikeUnderACommaDecimalLocale) {
    const std::string name = comma_decimal_locale();
    ASSERT_FALSE(name.empty()) << "no comma-decimal locale: install the Debian package locales";
    ASSERT_STREQ(std::localeconv()->decimal_point, ",") << name;
    double x = 0.0;
    EXPECT_EQ(text::classify_real("1.5e999", x, text::LeadingPlus::kRefused), text::RealText::kOverflow);
    EXPECT_EQ(text::classify_real("-2.5e400", x, text::LeadingPlus::kAccepted), text::RealText::kOverflow);
    EXPECT_EQ(text::classify_real("2.5e-400", x, text::LeadingPlus::kAccepted), text::RealText::kUnderflow);
    EXPECT_EQ(text::classify_real("1,5", x, text::LeadingPlus::kAccepted), text::RealText::kNotANumber);
    ASSERT_EQ(text::classify_real("1.5", x, text::LeadingPlus::kAccepted), text::RealText::kNumber);
    EXPECT_EQ(x, 1.5);
    EXPECT_EQ(*parse_double("-0.642227588171342"), -0.642227588171342);
    EXPECT_NE(why_not_a_number("1.5e999").find("at most 1.797693e+308"), std::string::npos)
        << why_not_a_number("1.5e999");
    EXPECT_EQ(error_of(std::string(kHeader) + "1.5,A,1.5e999,0,0,0,1.5,2.5,3.5,,,,0,1.5\n"),
              "2:7: f.csv:2:7: column 'qw': '1.5e999' is out of range: a number's magnitude is at most 1.797693e+308");
    std::setlocale(LC_NUMERIC, "C");
}

// The fast decimal path must give the very bits std::from_chars gives.
TEST(Csv, FastDecimalPathIsBitExact) {
    std::mt19937_64 rng(3);
    std::uniform_int_distribution<int> ndig(1, 17);
    std::uniform_int_distribution<int> digit(0, 9);
    for (int i = 0; i < 200000; ++i) {
        std::string s = (i % 2 == 0) ? "-" : "";
        const int int_digits = ndig(rng) % 6;
        const int frac_digits = ndig(rng);
        for (int k = 0; k < int_digits; ++k)
            s += static_cast<char>('0' + digit(rng));
        if (int_digits == 0)
            s += '0';
        s += '.';
        for (int k = 0; k < frac_digits; ++k)
            s += static_cast<char>('0' + digit(rng));
        double want = 0.0;
        std::from_chars(s.data(), s.data() + s.size(), want);
        const auto got = parse_double(s);
        ASSERT_TRUE(got) << s;
        ASSERT_EQ(std::memcmp(&*got, &want, sizeof want), 0) << s;
    }
    EXPECT_FALSE(parse_double("-"));
    EXPECT_FALSE(parse_double("."));
    EXPECT_FALSE(parse_double("1.2.3"));
    EXPECT_FALSE(parse_double("--1"));
}

// The fast fixed formatting of unit quantities must equal printf's.
TEST(Csv, FastFixedFormatEqualsPrintf) {
    std::mt19937_64 rng(4);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    char a[64];
    char b[64];
    for (int i = 0; i < 300000; ++i) {
        double x = u(rng);
        if (i % 3 == 0) {  // decimal ties and near-ties: k / 2e15 and neighbours
            x = std::nextafter(static_cast<double>(static_cast<long long>(x * 2e15)) / 2e15, i % 2 == 0 ? 2.0 : -2.0);
        }
        const std::string got(a, format_fixed(a, a + 64, x, 15));
        std::snprintf(b, sizeof b, "%.15f", x);
        ASSERT_EQ(got, std::string(b)) << x;
    }
    EXPECT_EQ(std::string(a, format_fixed(a, a + 64, -0.0, 15)), "-0.000000000000000");
    EXPECT_EQ(std::string(a, format_fixed(a, a + 64, 0.9999999999999999, 15)), "1.000000000000000");
}

TEST(ModelFile, ReadsTable2AndRoundTrips) {
    const ModelFile m = read_model_file(test::data_path("model_table2.csv"));
    EXPECT_TRUE(m.present[0] && m.present[1] && m.present[2]);
    EXPECT_FALSE(m.present[3]);
    EXPECT_FALSE(m.quadratic);
    EXPECT_DOUBLE_EQ(m.coefficients[2][kGamma][0], 11.7996);
    EXPECT_DOUBLE_EQ(m.coefficients[1][kAlpha][3], 0.240148);
    ModelFile q = m;
    q.quadratic = true;
    q.coefficients[0][kBeta][5] = -1.25e-3;
    const ModelFile back = parse_model("mem", format_model(q));
    EXPECT_EQ(back.coefficients, q.coefficients);  // bit-exact round trip
    EXPECT_TRUE(back.quadratic);
}

TEST(ModelFile, MalformedModels) {
    const auto err = [](const std::string& text) -> std::string {
        try {
            parse_model("m.csv", text);
        } catch (const text::InputError& e) {
            return e.what();
        }
        return "";
    };
    const std::string h = "chu,axis,c0,c1,c2,c3\n";
    expect_refusals(err, {{"", "empty model"}, {"chu,axis,c0,c1\n", "must have chu,axis,c0,c1,c2,c3"}, {h, "no rows"}});
    // Rows below the header.
    const auto rows_err = [&](const std::string& rows) { return err(h + rows); };
    expect_refusals(rows_err, {{"E,alpha,1,2,3,4\n", "m.csv:2:1: chu must be"},
                               {"A,delta,1,2,3,4\n", "m.csv:2:3: axis must be"},
                               {"A,alpha,1,2,x,4\n", "m.csv:2:13: column 'c2'"},
                               {"A,alpha,1,2,nan,4\n", "finite"},
                               {"A,alpha,1,2,3,4\nA,alpha,1,2,3,4\n", "second row for A alpha"},
                               {"A,alpha,1,2,3,4\nA,beta,1,2,3,4\n", "head A has no gamma row"},
                               {"A,alpha,1,2,3\n", "expected 6 fields"}});
}

// The writer's header is its column list, and a row it writes reads back
// exactly: the shortest digits, "nan" temperatures, empty velocity and
// confidence where not available.
TEST(SolutionsWriter, RowsReadBackExactly) {
    std::string joined;
    for (const std::string_view c : kSolutionsColumns) {
        joined += (joined.empty() ? "" : ",") + std::string(c);
    }
    EXPECT_EQ(joined, kSolutionsHeader);
    EXPECT_TRUE(is_solutions_column("confidence"));
    EXPECT_TRUE(is_solutions_column(kStatusColumn));
    EXPECT_FALSE(is_solutions_column("note"));
    EXPECT_FALSE(is_solutions_column("T"));

    const double nan = std::numeric_limits<double>::quiet_NaN();
    SolutionValues a;
    a.t = 447534187.831;
    a.chu = "B";
    a.q_chu_icrf = {0.1, -0.7, 1.0 / 3.0, 0.6};
    a.temperature = {20.25, nan, -1e-300};
    a.v_sc_kms = {nan, nan, nan};
    a.flags = 12;
    a.confidence = nan;
    SolutionValues b = a;
    b.chu = "D";
    b.temperature = {nan, nan, nan};
    b.v_sc_kms = {7.5, -0.0, 1.0 / 7.0};
    b.confidence = 3.25;
    std::string text(kSolutionsHeader);
    text += '\n';
    for (const SolutionValues& row : {a, b}) {
        append_solution_fields(text, row);
        text += '\n';
    }
    EXPECT_EQ(text.substr(text.find('\n') + 1, text.find('\n', text.find('\n') + 1) - text.find('\n') - 1),
              "447534187.831,B,0.1,-0.7,0.3333333333333333,0.6,20.25,nan,-1e-300,,,,12,");
    const std::vector<SolutionRecord> rows = parse_all(text);
    ASSERT_EQ(rows.size(), 2U);
    EXPECT_EQ(rows[0].t, a.t);
    EXPECT_EQ(rows[0].head, 1);
    EXPECT_EQ(rows[0].q_chu_icrf.y, 1.0 / 3.0);
    EXPECT_EQ(rows[0].q_chu_icrf.z, 0.6);
    EXPECT_EQ(rows[0].temperature[0], 20.25);
    EXPECT_FALSE(rows[0].temperature_present[1]);
    EXPECT_EQ(rows[0].temperature[2], -1e-300);
    EXPECT_EQ(rows[0].velocity_components, 0);
    EXPECT_EQ(rows[0].flags, 12);
    EXPECT_FALSE(rows[0].confidence_present);
    EXPECT_EQ(rows[1].head, 3);
    EXPECT_EQ(rows[1].velocity_components, 3);
    EXPECT_EQ(rows[1].v_sc_kms.z, 1.0 / 7.0);
    EXPECT_TRUE(std::signbit(rows[1].v_sc_kms.y));
    EXPECT_EQ(rows[1].confidence, 3.25);
    EXPECT_FALSE(rows[1].temperature_present[0]);
}

// for_each_solution_row: the header first, then every row with its fields as
// written (an extra column included), in file order, line numbers kept.
TEST(SolutionsReader, RowsWithTheirFields) {
    const auto dir = test::scratch_dir("rows");
    const std::string path = (dir / "s.csv").string();
    std::ofstream(path) << "t,chu,qw,qx,qy,qz,note\n1,A,1,0,0,0,first\n\n2,C,1,0,0,0,\"x, y\"\n";
    std::vector<std::string> seen;
    int headers = 0;
    for_each_solution_row(
        path,
        [&](const SolutionsReader& header) {
            ++headers;
            EXPECT_EQ(header.header().index("note"), 6);
            EXPECT_TRUE(seen.empty());
        },
        [&](const SolutionsReader& reader, const SolutionRecord& rec) {
            seen.push_back(std::to_string(rec.line) + ":" + std::string(rec.chu) + ":" +
                           std::string(reader.fields()[6]));
        },
        "");
    EXPECT_EQ(headers, 1);
    EXPECT_EQ(seen, (std::vector<std::string>{"2:A:first", "4:C:\"x, y\""}));
    std::ofstream(path) << "t,chu,qw,qx,qy,qz\n1,A,1,0,0,0\n2,C,1,0,zero,0\n";
    try {
        for_each_solution_row(
            path, [](const SolutionsReader&) {}, [](const SolutionsReader&, const SolutionRecord&) {}, "");
        ADD_FAILURE() << "a malformed row passed";
    } catch (const text::InputError& e) {
        EXPECT_EQ(e.line(), 3U);
        EXPECT_EQ(e.column(), 9U);
    }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ascorr::host
