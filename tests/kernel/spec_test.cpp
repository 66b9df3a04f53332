// The spec front end alone: lexer and parser (the checker is tested through the CLI).
#include "diagnostics.hpp"
#include "spec.hpp"

#include <gtest/gtest.h>

using namespace orogen::spec;

namespace {
Spec parse_text(const std::string& text, Diagnostics& d) {
    return parse(std::make_shared<Source>("t.orogen", text), d);
}
}  // namespace

TEST(Parser, ReadsTheIssueSpec) {
    Diagnostics d;
    const Spec s = parse_text(
        "orogen 1\nseed 7\ngrid 513 cell=30\n\n"
        "base = generate:diamond-square(roughness=0.6, amplitude=800)\n"
        "cut  = generate:fault(base, iterations=200, displacement=4)\n"
        "export:png(cut, path=\"cut.png\", bits=16)  # comment\n",
        d);
    ASSERT_FALSE(d.has_errors()) << d.format();
    EXPECT_EQ(*s.version, 1);
    EXPECT_EQ(*s.seed, 7u);
    EXPECT_EQ(s.grid_width, 513);
    EXPECT_EQ(s.grid_height, 513);
    EXPECT_EQ(s.grid_cell, 30.0);
    ASSERT_EQ(s.statements.size(), 3u);
    EXPECT_EQ(s.statements[1].name, "cut");
    EXPECT_EQ(s.statements[1].call.qualified(), "generate:fault");
    ASSERT_EQ(s.statements[1].call.inputs.size(), 1u);
    EXPECT_EQ(s.statements[1].call.inputs[0].name, "base");
    EXPECT_EQ(s.statements[1].call.params[1].value.number, 4.0);
    EXPECT_EQ(s.statements[2].name, "");
    EXPECT_EQ(s.statements[2].call.params[0].value.text, "cut.png");
    EXPECT_EQ(s.statements[2].call.where.line, 7);
    EXPECT_EQ(s.statements[2].call.where.column, 1);
    EXPECT_EQ(s.statements[2].call.where.length, 10);
}

TEST(Parser, ReadsPointsListsSideValuesAndMultiLineCalls) {
    Diagnostics d;
    const Spec s = parse_text(
        "orogen 1\ngrid 257x129\n"
        "m = generate:rmp(peaks=[(0.25, 0.5), (0.75, -1e-2)],\n"
        "                 method=voronoi, flag=true)\n"
        "export:vtk(sim.particles, path=\"p.vtp\")\n",
        d);
    ASSERT_FALSE(d.has_errors()) << d.format();
    EXPECT_EQ(s.grid_width, 257);
    EXPECT_EQ(s.grid_height, 129);
    const auto& peaks = s.statements[0].call.params[0].value;
    ASSERT_EQ(peaks.kind, Literal::Kind::list);
    ASSERT_EQ(peaks.items.size(), 2u);
    EXPECT_EQ(peaks.items[1].items[1].number, -0.01);
    EXPECT_EQ(s.statements[0].call.params[1].value.kind, Literal::Kind::word);
    EXPECT_EQ(s.statements[0].call.params[1].value.text, "voronoi");
    EXPECT_TRUE(s.statements[0].call.params[2].value.boolean);
    EXPECT_EQ(s.statements[1].call.inputs[0].full(), "sim.particles");
}

TEST(Parser, ReportsEverySyntaxErrorAtOnce) {
    Diagnostics d;
    parse_text("orogen 1\na = generate:fault(iterations=5 displacement=2)\nb = generate:fault(x=\"open\n"
               "c = generate:fault(x=3) $\nwibble 3\n",
               d);
    const std::string out = d.format();
    EXPECT_EQ(d.error_count(), 4) << out;
    EXPECT_NE(out.find("t.orogen:2:33: error: expected ',' or ')' in the call to generate:fault, found 'displacement'"),
              std::string::npos) << out;
    EXPECT_NE(out.find("t.orogen:3:22: error: unterminated string: add a closing '\"' on this line"), std::string::npos) << out;
    EXPECT_NE(out.find("t.orogen:4:25: error: unexpected character '$'"), std::string::npos) << out;
    EXPECT_NE(out.find("t.orogen:5:1: error: unknown statement 'wibble'"), std::string::npos) << out;
}

TEST(Parser, OverridesNameValueParamAndValue) {
    Diagnostics d;
    auto o = parse_override(std::make_shared<Source>("--set rivers.steps=500", "rivers.steps=500"), d);
    ASSERT_TRUE(o);
    EXPECT_EQ(o->target, "rivers");
    EXPECT_EQ(o->param, "steps");
    EXPECT_EQ(o->value.number, 500.0);
    EXPECT_EQ(o->value.where.column, 14);
    Diagnostics d2;
    EXPECT_FALSE(parse_override(std::make_shared<Source>("--set x", "rivers=500"), d2));
    EXPECT_EQ(d2.format(),
              "--set x:1:7: error: expected '.' between the value name and the parameter (NAME.PARAM=VALUE), found '='\n"
              "  rivers=500\n"
              "        ^\n");
}

TEST(Closest, SuggestsNearMissesOnly) {
    EXPECT_EQ(closest("displacment", {"iterations", "displacement"}), "displacement");
    EXPECT_EQ(closest("itreations", {"iterations", "displacement"}), "iterations");
    EXPECT_EQ(closest("zzz", {"iterations", "displacement"}), "");
}
