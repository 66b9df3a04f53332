// The spec front end alone: lexer and parser (the checker is tested through the CLI).
#include "spec/diagnostics.hpp"
#include "spec/spec.hpp"

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
    parse_text(
        "orogen 1\na = generate:fault(iterations=5 displacement=2)\nb = generate:fault(x=\"open\n"
        "c = generate:fault(x=3) $\nwibble 3\n",
        d);
    const std::string out = d.format();
    EXPECT_EQ(d.error_count(), 4) << out;
    EXPECT_NE(out.find("t.orogen:2:33: error: expected ',' or ')' in the call to generate:fault, found 'displacement'"),
              std::string::npos)
        << out;
    EXPECT_NE(out.find("t.orogen:3:22: error: unterminated string: add a closing '\"' on this line"), std::string::npos)
        << out;
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
              "--set x:1:7: error: expected '.' between the value name and the parameter (NAME.PARAM=VALUE; an unnamed "
              "node by its label, e.g. export:png#2.bits=8), found '='\n"
              "  rivers=500\n"
              "        ^\n");
}

// An unnamed node is reached by its label, as the timing table prints it (issue 32, item 3).
TEST(Parser, OverridesReachUnnamedNodesByTheirLabel) {
    Diagnostics d;
    auto o = parse_override(std::make_shared<Source>("--set export:video.quality=23", "export:video.quality=23"), d);
    ASSERT_TRUE(o) << d.format();
    EXPECT_EQ(o->target, "export:video");
    EXPECT_EQ(o->target_where.length, 12);
    EXPECT_EQ(o->param, "quality");
    EXPECT_EQ(o->value.number, 23.0);
    o = parse_override(std::make_shared<Source>("--set export:png#2.bits=8", "export:png#2.bits=8"), d);
    ASSERT_TRUE(o) << d.format();
    EXPECT_EQ(o->target, "export:png#2");
    EXPECT_EQ(o->target_where.length, 12);
    EXPECT_EQ(o->param, "bits");
    Diagnostics d2;
    EXPECT_FALSE(parse_override(std::make_shared<Source>("--set x", "export:png#x.bits=8"), d2));
    EXPECT_NE(d2.format().find("expected the label's number after '#'"), std::string::npos) << d2.format();
}

// A call where an input goes is hoisted into an unnamed statement just before its reader (issue 32, item 2);
// a statement on the next line after a '(' that is never closed is still that, not an input.
TEST(Parser, ACallWhereAnInputGoesBecomesANestedStatement) {
    Diagnostics d;
    const Spec s = parse_text(
        "orogen 1\n"
        "spin = render:turntable(t, frames=2)\n"
        "export:video(render:bloom(render:blur(spin, axis=x)), path=\"t.mp4\")\n"
        "export:png(\n  render:bloom(x),\n  path=\"x.png\")\n",
        d);
    ASSERT_FALSE(d.has_errors()) << d.format();
    ASSERT_EQ(s.statements.size(), 6u);
    EXPECT_EQ(s.statements[1].call.qualified(), "render:blur");
    EXPECT_TRUE(s.statements[1].nested);
    EXPECT_EQ(s.statements[1].call.inputs[0].name, "spin");
    EXPECT_EQ(s.statements[2].call.qualified(), "render:bloom");
    EXPECT_TRUE(s.statements[2].nested);
    ASSERT_EQ(s.statements[2].call.inputs.size(), 1u);
    EXPECT_EQ(s.statements[2].call.inputs[0].statement, 1);
    EXPECT_EQ(s.statements[3].call.qualified(), "export:video");
    EXPECT_FALSE(s.statements[3].nested);
    EXPECT_EQ(s.statements[3].call.inputs[0].statement, 2);
    EXPECT_EQ(s.statements[3].call.params[0].value.text, "t.mp4");
    EXPECT_TRUE(s.statements[4].nested);  // the multi-line call's inner one
    EXPECT_EQ(s.statements[5].call.inputs[0].statement, 4);

    Diagnostics d2;
    parse_text("orogen 1\nc = generate:fault(\nexport:png(base, path=\"x.png\")\n", d2);
    EXPECT_EQ(d2.error_count(), 1) << d2.format();
    EXPECT_NE(d2.format().find("t.orogen:2:19: error: this '(' of the call to generate:fault is never closed"),
              std::string::npos)
        << d2.format();
    Diagnostics d3;
    parse_text("orogen 1\nexport:png(generate:fault().plates, path=\"x.png\")\n", d3);
    EXPECT_NE(d3.format().find("name the value first"), std::string::npos) << d3.format();
    // Nesting is bounded (the parser recurses): 64 levels parse, 65 are one error.
    auto nested = [](int depth) {
        std::string text = "orogen 1\nv = generate:fault()\nexport:png(";
        for (int i = 0; i < depth; ++i) text += "erode:thermal(";
        text += "v";
        for (int i = 0; i < depth; ++i) text += ")";
        return text + ", path=\"x.png\")\n";
    };
    Diagnostics d4;
    EXPECT_EQ(parse_text(nested(64), d4).statements.size(), 66u) << d4.format();
    EXPECT_FALSE(d4.has_errors()) << d4.format();
    Diagnostics d5;
    parse_text(nested(65), d5);
    EXPECT_EQ(d5.error_count(), 1) << d5.format();
    EXPECT_NE(d5.format().find("calls are nested more than 64 deep"), std::string::npos) << d5.format();
}

TEST(Closest, SuggestsNearMissesOnly) {
    EXPECT_EQ(closest("displacment", {"iterations", "displacement"}), "displacement");
    EXPECT_EQ(closest("itreations", {"iterations", "displacement"}), "iterations");
    EXPECT_EQ(closest("zzz", {"iterations", "displacement"}), "");
}
