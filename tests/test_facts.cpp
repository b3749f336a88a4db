// tests/test_facts.cpp: one place for each fact (issue 14). The heads
// (ascorr/heads.hpp) are defined once; what can include them derives from them,
// and what cannot (documentation, the HAL's role names) is checked here against
// them, so a copy that drifts fails this test.
#include <gtest/gtest.h>

#include <cctype>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/heads.hpp"
#include "ascorr_hal/channel_config.hpp"
#include "ascorr_host/solutions_csv.hpp"

namespace ascorr {
namespace {

std::string source_file(const std::string& rel) {
    std::ifstream f(std::string(ASCORR_SOURCE_DIR) + "/" + rel, std::ios::binary);
    EXPECT_TRUE(f.good()) << rel;
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

char first_letter() {
    return kHeadLetters[0];
}
char last_letter() {
    return kHeadLetters[kMaxHeads - 1];
}

// ---- Heads

TEST(Heads, LettersAndIndicesMapBothWays) {
    std::set<char> seen;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const char c = head_letter(h);
        EXPECT_TRUE(std::isupper(static_cast<unsigned char>(c)) != 0) << int(h);
        EXPECT_TRUE(seen.insert(c).second) << "letter " << c << " twice";
        EXPECT_EQ(head_index(c), h);
        EXPECT_EQ(host::head_from_name(std::string(1, c)), h);
        EXPECT_EQ(host::head_name(h), c);
    }
    EXPECT_EQ(head_letter(kMaxHeads), '?');
    EXPECT_EQ(head_letter(kUnknownHead), '?');
    for (int c = 0; c < 256; ++c) {  // everything else is no head
        if (seen.count(static_cast<char>(c)) == 0) {
            EXPECT_EQ(head_index(static_cast<char>(c)), kUnknownHead) << c;
        }
    }
    EXPECT_EQ(host::head_from_name(std::string(1, first_letter()) + first_letter()), kUnknownHead);
    EXPECT_EQ(host::head_from_name(""), kUnknownHead);
    EXPECT_EQ(host::head_from_name(std::string(1, static_cast<char>(std::tolower(first_letter())))), kUnknownHead);
}

TEST(Heads, ChoicesTextListsEveryLetter) {
    std::string want;  // built here by joining, not by the header's loop
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        want += std::string(h == 0 ? "" : h + 1 == kMaxHeads ? " or " : ", ") + kHeadLetters[h];
    }
    EXPECT_EQ(std::string(kHeadChoices.text), want);
    EXPECT_LT(want.size(), sizeof(kHeadChoices.text));
}

// The HAL's roles cannot be generated (an enum): one kChu<letter> per head is
// static_asserted in channel_config.hpp, and its name is checked here.
TEST(Heads, HalRolesAreOnePerHeadNamedByItsLetter) {
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const auto r = static_cast<std::uint8_t>(hal::chu_role(h));
        ASSERT_LT(r, hal::kRoleCount);
        EXPECT_EQ(std::string(hal::kRoleNames[r]),
                  std::string("chu_") + static_cast<char>(std::tolower(static_cast<unsigned char>(head_letter(h)))));
    }
}

// Where the documentation states the heads, in the words it uses; {first},
// {last}, {next} (the letter after the last), {count} and {last_index} are
// filled in from heads.hpp. A head added to heads.hpp fails this test until
// these statements are brought along.
struct DocStatement {
    const char* file;
    const char* text;
};

std::string fill(std::string s) {
    const auto put = [&](const std::string& key, const std::string& value) {
        for (std::size_t p = s.find(key); p != std::string::npos; p = s.find(key, p + value.size())) {
            s.replace(p, key.size(), value);
        }
    };
    put("{first}", std::string(1, first_letter()));
    put("{last}", std::string(1, last_letter()));
    put("{next}", std::string(1, static_cast<char>(last_letter() + 1)));
    put("{count}", std::to_string(kMaxHeads));
    put("{last_index}", std::to_string(kMaxHeads - 1));
    return s;
}

TEST(Heads, DocumentationStatesTheHeadsOfHeadsHpp) {
    const std::vector<DocStatement> statements = {
        {"docs/contract.md", "`{first}`, `B` or `C` (`{last}` accepted too)"},
        {"docs/contract.md", "`chu` (n,) of `\"{first}\"`…`\"{last}\"` strings or head indices 0…{last_index}"},
        {"DEVELOPERS.md", "`chu` not {first}–{last}, head index ≥ {count}"},
        {"DEVELOPERS.md", "head `\"{next}\"` or index ≥ {count}"},
        {"firmware/link-protocol.md", "head u8 (0–{last_index})"},
        {"hal/linux/include/ascorr_hal_linux/config_file.hpp", "chu_a … chu_{last_lower}"},
        {"hal/linux/include/ascorr_hal_linux/simulated_source.hpp", "({first}–{last})"},
    };
    for (const DocStatement& d : statements) {
        std::string want = fill(d.text);
        const std::string key = "{last_lower}";
        if (const auto p = want.find(key); p != std::string::npos) {
            want.replace(p, key.size(), std::string(1, static_cast<char>(std::tolower(last_letter()))));
        }
        EXPECT_NE(source_file(d.file).find(want), std::string::npos)
            << d.file << " no longer says \"" << want << "\" (ascorr/heads.hpp): bring it in step";
    }
}

// Any other range of head letters in the documentation ("A–D", "'A'..'D'",
// "\"A\"…\"D\"") must end at the last head. Ranges ending at B or C are the
// inter-boresight pairs of Swarm's three heads (A–B, A–C), not head ranges.
// Returns the ranges that end elsewhere, and counts every range seen.
std::vector<std::string> stray_ranges(const std::string& text, int& seen) {
    const std::regex range(std::string("(?:^|[^A-Za-z0-9_])[`'\"]{0,2}") + first_letter() +
                           "[`'\"]{0,2}(–|\\.\\.|…)[`'\"]{0,2}([A-Z])\\b");
    std::vector<std::string> bad;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), range); it != std::sregex_iterator(); ++it) {
        ++seen;
        const char end = (*it)[2].str()[0];
        const bool pair = kMaxHeads >= 3 && (end == kHeadLetters[1] || end == kHeadLetters[2]);
        if (end != last_letter() && !pair) {
            bad.push_back(it->str());
        }
    }
    return bad;
}

TEST(Heads, NoLetterRangeInTheDocumentationEndsElsewhere) {
    int seen = 0;
    for (const char* file : {"README.md", "DEVELOPERS.md", "docs/contract.md", "firmware/link-protocol.md",
                             "python/ascorr/__init__.py", "python/ascorr/__init__.pyi"}) {
        for (const std::string& r : stray_ranges(source_file(file), seen)) {
            ADD_FAILURE() << file << ": '" << r << "' is a range of heads that does not end at " << last_letter()
                          << " (ascorr/heads.hpp)";
        }
    }
    EXPECT_GT(seen, 2);  // the statements above are found, so the scan is not vacuous
    // Mutation: a range one head too long is caught.
    int m = 0;
    EXPECT_EQ(stray_ranges(fill("heads {first}–{next}, `\"{first}\"`…`\"{last}\"`"), m).size(), 1U);
    EXPECT_EQ(m, 2);
}

}  // namespace
}  // namespace ascorr
