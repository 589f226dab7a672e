// SPDX-License-Identifier: BSD-3-Clause
// The IC model language (.icm) front end: the thesis' fixtures in notation mode, the models of
// Data/Models/icm, one test per construct, the diagnostics (line and column asserted) and the
// limits.
#include "Lang/HyperFun.h"
#include "Lang/Icm.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

using namespace ictk;
using namespace ictk::lang;
namespace fs = std::filesystem;

namespace
{

std::string slurp(const fs::path& p)
{
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

const fs::path fixtures = ICTK_ICM_FIXTURES_DIR;
const fs::path models = fs::path(ICTK_DATA_DIR) / "Models" / "icm";

std::string errorsOf(const std::string& text, bool notation = false)
{
  try
  {
    if (notation)
    {
      parseIcmNotation(text, "t.icm");
    }
    else
    {
      readIcm(text, "t.icm");
    }
  }
  catch (const ParseError& e)
  {
    return e.what();
  }
  return {};
}

IcmModel ok(const std::string& text)
{
  try
  {
    return readIcm(text, "t.icm");
  }
  catch (const ParseError& e)
  {
    ADD_FAILURE() << e.what();
    return {};
  }
}

// A model around a body: two cells A and B (A has parameters p and v), an event E with one
// parameter, a template T and an instance K using it.
std::string withCells(const std::string& instanceBody, const std::string& extra = {})
{
  return "EVENTS { E { parameters { amount : REAL(1); } priority = 2; } }\n"
         "CELLS {\n"
         "  A { type = F-CELL; dim = 2D; parameters { p : REAL(0); v : VECTOR3(0, 0, 0); } }\n"
         "  B { type = B-CELL; dim = 2D; }\n"
         "}\n"
         "STATE_PARAMETERS { flag : BOOL(false); }\n"
         "T : TEMPLATE_IC { CELLS { A B; } }\n" +
    extra + "K : T {\n" + instanceBody + "\n}\n";
}

std::string inUpdate(const std::string& code)
{
  return withCells(
    "REACTIONS { update(REAL globalT, REAL localT, REAL lifeT, REAL dt) {\n" + code + "\n} }");
}

} // namespace

// ---- the thesis' fixtures (notation mode) ------------------------------------------------------

TEST(IcmNotation, AcceptsNormalisedFixtures)
{
  if (!fs::exists(fixtures))
  {
    GTEST_SKIP() << "no fixtures at " << fixtures;
  }
  std::vector<std::string> names = { "appC_andyhausen_template.icm", "ch5_2_INITIAL_TEMPLATE.icm",
    "ch5_2_K1.icm", "ch5_2_K3.icm", "ch5_1_cells.icm", "ch5_1_state_parameters.icm",
    "ch5_2_state_parameters.icm", "ch5_4_5_instance1_reactions.icm",
    "ch5_4_5_instance2_reactions.icm" };
  for (const auto& entry : fs::directory_iterator(fixtures))
  {
    const std::string n = entry.path().filename().string();
    if (n.rfind("norm_", 0) == 0 || (n.rfind("full_", 0) == 0 && n.find(".norm.") != n.npos))
    {
      names.push_back(n);
    }
  }
  EXPECT_GE(names.size(), 30u);
  for (const std::string& n : names)
  {
    SCOPED_TRACE(n);
    EXPECT_EQ(errorsOf(slurp(fixtures / n), true), "");
  }
}

TEST(IcmNotation, RejectsDamagedFixturesWithALocation)
{
  if (!fs::exists(fixtures))
  {
    GTEST_SKIP();
  }
  const char* damaged[] = { "appB_standin_part1_cells_template_instance1.icm",
    "appB_standin_part2_instance2.icm", "appC_andyhausen_instance1_EGG_GOING_DOWN.icm",
    "appC_andyhausen_instance2_EGG_ERODING.icm", "appC_andyhausen_instance3_ANDY_OUT.icm",
    "ch5_1_K1.icm", "ch5_1_K2.icm", "ch5_1_K3.icm", "ch5_2_K2.icm", "ch5_2_K4.icm",
    "ch5_2_P_point.icm", "ch5_2_cells.icm", "ch5_6_2_andyhausen_cells.icm", "ch5_4_5_timespans.icm",
    "ch5_3_4_STB_CELL_truncated.icm" };
  for (const char* n : damaged)
  {
    SCOPED_TRACE(n);
    try
    {
      parseIcmNotation(slurp(fixtures / n), n);
      ADD_FAILURE() << "accepted";
    }
    catch (const ParseError& e)
    {
      ASSERT_FALSE(e.diagnostics().empty());
      EXPECT_GT(e.diagnostics()[0].where.line, 0);
      EXPECT_GT(e.diagnostics()[0].where.column, 0);
    }
  }
  // The truncated STB cell ends in the middle of a block.
  const std::string stb = errorsOf(slurp(fixtures / "ch5_3_4_STB_CELL_truncated.icm"), true);
  EXPECT_NE(stb.find("end of file"), std::string::npos) << stb;
}

TEST(IcmNotation, FixtureStructure)
{
  if (!fs::exists(fixtures))
  {
    GTEST_SKIP();
  }
  const IcmModel m =
    parseIcmNotation(slurp(fixtures / "full_andyhausen_5_6_2_appC.norm.icm"), "andyhausen.icm");
  ASSERT_EQ(m.instances.size(), 4u);
  EXPECT_TRUE(m.instances[0].isTemplate);
  EXPECT_EQ(m.instances[0].name.text, "TEMPLATE_IC1");
  const auto& deps = m.instances[0].relations[0].dependency;
  ASSERT_EQ(deps.size(), 5u);
  EXPECT_TRUE(deps[1].hasPriority);
  EXPECT_DOUBLE_EQ(deps[1].priority, 0.5);
  EXPECT_DOUBLE_EQ(deps[0].priority, 1.0);
  EXPECT_EQ(m.instances[3].name.text, "ANDY_OUT");
  // The verbatim `dim ::= 4D;` and `type = F-CELL;` give the same kind of property.
  const IcmModel a = parseIcmNotation("CELLS { X { dim ::= 4D; type = F-CELL; } }", "a.icm");
  ASSERT_EQ(a.cells[0].defs[0].properties.size(), 2u);
  EXPECT_EQ(a.cells[0].defs[0].properties[0].values[0]->kind, icm::Expr::Kind::Dim);
  EXPECT_EQ(a.cells[0].defs[0].properties[0].values[0]->number, 4);
  EXPECT_EQ(a.cells[0].defs[0].properties[1].values[0]->text, "F-CELL");
}

TEST(IcmNotation, PlaceholdersOnlyInNotationMode)
{
  const std::string text = "CELLS { X { domain = {...}; parameters { translation(...); } } }";
  EXPECT_EQ(errorsOf(text, true), "");
  const std::string e = errorsOf(text);
  EXPECT_NE(e.find("t.icm:1:23: error: placeholder '...'"), std::string::npos) << e;
}

// ---- the models --------------------------------------------------------------------------------

TEST(IcmModels, AllParse)
{
  std::size_t count = 0;
  for (const auto& entry : fs::directory_iterator(models))
  {
    if (entry.path().extension() != ".icm")
    {
      continue;
    }
    SCOPED_TRACE(entry.path().string());
    ++count;
    try
    {
      const IcmModel m = readIcmFile(entry.path().string());
      EXPECT_FALSE(m.instances.empty());
      EXPECT_EQ(m.directory, entry.path().parent_path().string());
    }
    catch (const ParseError& e)
    {
      ADD_FAILURE() << e.what();
    }
  }
  EXPECT_GE(count, 4u);
}

// Every inline HyperFun shape and every file("...hf") of the models compiles.
TEST(IcmModels, ShapesCompile)
{
  for (const auto& entry : fs::directory_iterator(models))
  {
    if (entry.path().extension() != ".icm")
    {
      continue;
    }
    const std::string text = slurp(entry.path());
    const IcmModel m = readIcm(text, entry.path().string());
    std::vector<const icm::CellDef*> cells;
    for (const auto& s : m.cells)
    {
      for (const auto& c : s.defs)
      {
        cells.push_back(&c);
      }
    }
    for (const auto& in : m.instances)
    {
      for (const auto& s : in.cells)
      {
        for (const auto& c : s.defs)
        {
          cells.push_back(&c);
        }
      }
    }
    for (const icm::CellDef* c : cells)
    {
      const icm::Property* shape = c->property("shape");
      if (!shape)
      {
        continue;
      }
      SCOPED_TRACE(c->name.text);
      if (shape->isHyperFun)
      {
        EXPECT_NO_THROW(readHyperFun(shape->hyperFunText, c->name.text + ".hf"));
        // The position is that of the text after '{'.
        EXPECT_GT(shape->hyperFunPos.line, shape->pos.line - 1);
      }
      else if (shape->values[0]->kind == icm::Expr::Kind::Call && shape->values[0]->text == "file")
      {
        const fs::path p = entry.path().parent_path() / shape->values[0]->kids[1]->text;
        EXPECT_NO_THROW(readHyperFunFile(p.string()));
      }
    }
  }
}

TEST(IcmModels, DiskRectangleInstances)
{
  const IcmModel m = readIcmFile((models / "ch5_1_disk_rectangle.icm").string());
  EXPECT_EQ(m.name.text, "DISK_RECTANGLE");
  ASSERT_EQ(m.instances.size(), 4u);
  EXPECT_TRUE(m.instances[0].isTemplate);
  EXPECT_EQ(m.instances[1].name.text, "K1");
  EXPECT_EQ(m.instances[2].name.text, "K2");
  EXPECT_EQ(m.instances[3].name.text, "K3");
  // K3 lists the five T-cells of the overlap.
  ASSERT_EQ(m.instances[3].cells[0].refs.size(), 5u);
  EXPECT_EQ(m.instances[3].cells[0].refs[0].text, "KFL_half_disk");
  const icm::CellDef* disk = m.cell("LHKF");
  ASSERT_NE(disk, nullptr);
  const icm::Property* shape = disk->property("shape");
  ASSERT_TRUE(shape && shape->isHyperFun);
  EXPECT_NE(shape->hyperFunText.find("disk = 1 - x[1]^2 - x[2]^2;"), std::string::npos);
  // The HyperFun disk: 1 - x^2 - y^2 is 1 at the centre and 0 on the unit circle.
  const auto hf = readHyperFun(shape->hyperFunText, "disk.hf");
  EXPECT_EQ(hf.name, "disk");
  ASSERT_EQ(m.instances[2].predicates.size(), 1u);
  EXPECT_EQ(m.instances[2].predicates[0].formals.size(), 3u);
}

TEST(IcmModels, DependencyModel)
{
  const IcmModel m = readIcmFile((models / "ch5_2_dependency.icm").string());
  const icm::Instance* t = m.instance("INITIAL_TEMPLATE");
  ASSERT_NE(t, nullptr);
  const auto& deps = t->relations[0].dependency;
  ASSERT_EQ(deps.size(), 1u);
  EXPECT_TRUE(deps[0].hierarchical);
  EXPECT_EQ(deps[0].name.text, "LINE_DISK");
  EXPECT_EQ(deps[0].ends[0]->text, "OM"); // the master first
  EXPECT_EQ(deps[0].ends[1]->text, "LHKF");
  EXPECT_EQ(m.instance("K4")->base.text, "INITIAL_TEMPLATE");
  ASSERT_EQ(m.animations.size(), 1u);
  EXPECT_EQ(m.animations[0].name.text, "animCurve1");
  ASSERT_NE(m.animations[0].property("keys"), nullptr);
  EXPECT_EQ(m.animations[0].property("keys")->values.size(), 2u);
}

TEST(IcmModels, NewtonsCradle)
{
  const IcmModel m = readIcmFile((models / "newtons_cradle.icm").string());
  const icm::Instance* contact = m.instance("CONTACT");
  ASSERT_NE(contact, nullptr);
  const auto& deps = contact->relations[0].dependency;
  ASSERT_EQ(deps.size(), 2u);
  EXPECT_DOUBLE_EQ(deps[0].priority, 2.0);
  EXPECT_DOUBLE_EQ(deps[1].priority, 1.0);
  EXPECT_EQ(deps[1].name.text, "p2");
  ASSERT_EQ(m.events.size(), 1u);
  EXPECT_EQ(m.events[0].name.text, "COLLISION");
  EXPECT_EQ(m.cell("B2")->source.text, "B1");
  ASSERT_EQ(contact->reactions.size(), 2u);
  EXPECT_EQ(contact->reactions[1].name.text, "react");
  EXPECT_EQ(contact->reactions[1].formals[0].type, "COLLISION");
  // the balls' own updates, replaced while they touch
  ASSERT_EQ(contact->cells.size(), 1u);
  ASSERT_EQ(contact->cells[0].reactions.size(), 2u);
  EXPECT_EQ(contact->cells[0].reactions[0].cell.text, "B1");
  EXPECT_EQ(m.cycles.text, "previous");
}

TEST(IcmModels, Andyhausen)
{
  const IcmModel m = readIcmFile((models / "andyhausen.icm").string());
  ASSERT_EQ(m.instances.size(), 4u);
  EXPECT_EQ(m.instances[1].name.text, "EGG_GOING_DOWN");
  EXPECT_EQ(m.instances[2].name.text, "EGG_ERODING");
  EXPECT_EQ(m.instances[3].name.text, "ANDY_OUT");
  const auto& deps = m.instances[0].relations[0].dependency;
  ASSERT_EQ(deps.size(), 7u); // the chain's five, and the yolk and the white on the contents
  EXPECT_DOUBLE_EQ(deps[1].priority, 0.5);
  EXPECT_TRUE(deps[5].hierarchical);
  EXPECT_TRUE(deps[6].hierarchical);
  // EGG_GOING_DOWN uses the template's cells without the melting egg.
  const auto& use = m.instances[1].cells[0].uses[0];
  ASSERT_EQ(use.minus.size(), 1u);
  EXPECT_EQ(use.minus[0].text, "Melting_egg");
  // ANDY_OUT: the skeleton on the hook, Andy on the skeleton and posed by its matrices, and the
  // hand's angle turning the handle (the thesis' indexed path Andy.skeleton["hand"].rotationZ is
  // read in its fixture appC_andyhausen_instance3_ANDY_OUT.icm).
  const auto& andy = m.instances[3].relations[0].dependency;
  ASSERT_EQ(andy.size(), 4u);
  EXPECT_TRUE(andy[0].hierarchical);
  EXPECT_TRUE(andy[1].hierarchical);
  EXPECT_EQ(andy[3].ends[0]->kind, icm::Expr::Kind::Member);
  EXPECT_EQ(andy[3].ends[0]->text, "handAngle");
  EXPECT_EQ(andy[3].ends[1]->text, "alpha");
  EXPECT_EQ(m.instances[3].relations[0].dependencyUses[0].minus.size(), 2u);
  // The egg's containment.
  ASSERT_EQ(m.instances[1].relations[0].containment.size(), 1u);
  EXPECT_EQ(m.instances[1].relations[0].containment[0].ends[0]->text, "Eggshell");
}

// ---- constructs
// ----------------------------------------------------------------------------------

TEST(IcmConstructs, Lexical)
{
  // `::=` and `=`, both comment styles, cell types and dimensions as single tokens, exponents,
  // the thesis' `IC::` prefix, U without braces.
  const IcmModel m = ok("/* a\n block comment */ CELLS { A { type ::= F-CELL; dim = 2D; } // x\n"
                        "B { type = B-CELL; parameters { k : REAL(1e-3); } } }\n"
                        "EVENTS { E { } }\n"
                        "T : TEMPLATE_IC { CELLS { A; } }\n"
                        "K { CELLS { USE T.CELLS U B; } REACTIONS { init(REAL g) {"
                        " IC::fireEvent(E); B.k = 2.5e+1 - -1; } } }");
  const auto& a = m.cells[0].defs[0];
  EXPECT_EQ(a.pos.line, 2);
  EXPECT_EQ(a.properties[0].values[0]->kind, icm::Expr::Kind::CellType);
  EXPECT_EQ(a.properties[0].values[0]->text, "F-CELL");
  EXPECT_EQ(a.properties[1].values[0]->kind, icm::Expr::Kind::Dim);
  EXPECT_DOUBLE_EQ(m.cells[0].defs[1].parameters[0].args[0]->number, 1e-3);
  EXPECT_EQ(m.instance("K")->cells[0].uses[0].plus[0].text, "B");
  EXPECT_EQ(m.instance("K")->reactions[0].body[0]->value->text, "IC::fireEvent");
}

TEST(IcmConstructs, TimespansAndEvents)
{
  const IcmModel m = ok("name = M;\nTIMESPANS { a : TIMESPAN; b : TIMESPAN(0, 5); "
                        "c : TIMESPAN({0, 1}, {2, 3}, 2.0); }\n"
                        "EVENTS { HIT { parameters { force : REAL(0); where : VECTOR3(0,0,0); }"
                        " priority = 3; timespan = b; } }");
  EXPECT_EQ(m.name.text, "M");
  ASSERT_EQ(m.timespans.size(), 3u);
  EXPECT_TRUE(m.timespans[0].args.empty());
  EXPECT_EQ(m.timespans[2].args.size(), 3u);
  ASSERT_EQ(m.events.size(), 1u);
  EXPECT_EQ(m.events[0].parameters.size(), 2u);
  EXPECT_EQ(m.events[0].properties[0].name, "priority");
  EXPECT_EQ(m.events[0].properties[0].pos.line, 3);
}

TEST(IcmConstructs, CellsSourcesAndProperties)
{
  const IcmModel m = ok("TIMESPANS { s : TIMESPAN(0, 1); }\n"
                        "CELLS {\n"
                        "  A { type = P-CELL; shape = point(1, 2, 3); dim = 0D;"
                        " domain = { 0, 0, 1, 1 }; lifespan = {0, 2}, {3, 4}; priority = 2;\n"
                        "      parameters { translation(1, 0, 0); rotation(0, 0, 0); scale(2);"
                        " k : REAL(1.5); n : INT(3); f : BOOL(true); s : STRING(\"x\");"
                        " list : array of TRANSFORM; } }\n"
                        "  B <- A { lifespan = s; }\n"
                        "  C { shape = file(\"m.xml\"); }\n"
                        "  D { shape = blend(A, C, 0.5); }\n"
                        "}");
  ASSERT_EQ(m.cells[0].defs.size(), 4u);
  const icm::CellDef& a = m.cells[0].defs[0];
  EXPECT_EQ(a.properties.size(), 6u);
  EXPECT_EQ(a.parameters.size(), 8u);
  EXPECT_TRUE(a.parameters[7].array);
  EXPECT_EQ(m.cells[0].defs[1].source.text, "A");
  EXPECT_EQ(m.cells[0].defs[1].source.pos.line, 5);
  EXPECT_EQ(m.cells[0].defs[1].source.pos.column, 8);
}

TEST(IcmConstructs, InlineHyperFunKeepsTextAndPosition)
{
  const std::string text = "CELLS {\n  S { type = F-CELL; shape = hyperfun {\n"
                           "s(x[3], a[1]) { s = 1 - x[1]^2 - x[2]^2 - x[3]^2; -- {comment}\n}"
                           " }; dim = 3D; }\n}";
  const IcmModel m = ok(text);
  const icm::Property* p = m.cells[0].defs[0].property("shape");
  ASSERT_TRUE(p && p->isHyperFun);
  EXPECT_EQ(p->hyperFunPos.line, 2);
  EXPECT_EQ(p->hyperFunPos.column, 40);
  EXPECT_EQ(p->hyperFunText.substr(0, 2), "\ns");
  EXPECT_NO_THROW(readHyperFun(p->hyperFunText, "s.hf"));
  EXPECT_EQ(m.cells[0].defs[0].property("dim")->values[0]->text, "3D");
}

TEST(IcmConstructs, TemplatesInstancesUseAndRelations)
{
  const IcmModel m = ok(withCells("CELLS { USE T.CELLS \\ { B } U { B }; }\n"
                                  "RELATIONS {\n"
                                  "  containment { A B inside; }\n"
                                  "  boundary { USE T.RELATIONS.boundary; }\n"
                                  "  dependency { USE T.RELATIONS.dependency; USE T.Rd[A, B];\n"
                                  "    A.p B.translation 0.5 named; B A HIERARCHICAL; "
                                  "A.v B.scale; A.p B.rotation linkName; }\n"
                                  "}"));
  const icm::Instance* k = m.instance("K");
  ASSERT_NE(k, nullptr);
  EXPECT_EQ(k->base.text, "T");
  EXPECT_EQ(k->cells[0].uses[0].minus[0].text, "B");
  EXPECT_EQ(k->cells[0].uses[0].plus[0].text, "B");
  const auto& r = k->relations[0];
  EXPECT_EQ(r.containment[0].name.text, "inside");
  ASSERT_EQ(r.dependency.size(), 4u);
  EXPECT_DOUBLE_EQ(r.dependency[0].priority, 0.5);
  EXPECT_EQ(r.dependency[0].name.text, "named");
  EXPECT_TRUE(r.dependency[1].hierarchical);
  EXPECT_FALSE(r.dependency[2].hasPriority);
  EXPECT_DOUBLE_EQ(r.dependency[2].priority, 1.0);
  EXPECT_EQ(r.dependency[3].name.text, "linkName");
  EXPECT_EQ(r.dependencyUses.size(), 2u);
}

TEST(IcmConstructs, Attributes)
{
  const IcmModel m = ok(withCells("ATTRIBUTES { USE T.ATTRIBUTES; own = ownMapper;"
                                  " default = own; RELATIONS { A own; B.attributes = shared; } }",
    "ATTRIBUTES { shared = sharedMapper; colour <- shared { mapping = colourMap; dim = 3D; } }\n"));
  ASSERT_EQ(m.attributes.size(), 1u);
  EXPECT_EQ(m.attributes[0].bindings[0].second.text, "sharedMapper");
  EXPECT_EQ(m.attributes[0].defs[0].source.text, "shared");
  const auto& a = m.instance("K")->attributes[0];
  EXPECT_EQ(a.defaultAttribute.text, "own");
  ASSERT_EQ(a.links.size(), 2u);
  EXPECT_EQ(a.links[1].ends[1]->text, "shared");
}

TEST(IcmConstructs, StateParametersAndAliases)
{
  const IcmModel m = ok(withCells("STATE_PARAMETERS { count : INT(0); A.p pAlias; extra ex; }\n"
                                  "parameters { extra : REAL(2); }\n"
                                  "REACTIONS { update(REAL g, REAL l, REAL life, REAL dt) {"
                                  " count += 1; flag = pAlias > 0.5; } }"));
  const icm::Instance* k = m.instance("K");
  ASSERT_EQ(k->stateParameters.size(), 3u);
  // The instance's parameters are visible in the custom reactions inside its CELLS too.
  ok(withCells("STATE_PARAMETERS { s : REAL(0); } parameters { q : REAL(1); }\n"
               "CELLS { REACTIONS { A.update(REAL g, REAL l, REAL f, REAL dt) { p = s + q; } } }"));
  EXPECT_EQ(k->stateParameters[1].kind, icm::ParamDecl::Kind::Alias);
  EXPECT_EQ(k->stateParameters[1].name.text, "pAlias");
  EXPECT_EQ(m.stateParameters.size(), 1u);
}

TEST(IcmConstructs, ReactionsAllKinds)
{
  const IcmModel m = ok(withCells(
    "REACTIONS {\n"
    "  init(REAL globalT) { flag = false; }\n"
    "  terminate(REAL globalT) { flag = true; }\n"
    "  update(REAL globalT, REAL localT, REAL lifeT, REAL dt) { A.p += dt; }\n"
    "  updatePost(REAL globalT, REAL localT, REAL lifeT, REAL dt) { A.p *= 0.5; }\n"
    "  react(E e, REAL globalT, REAL localT, REAL lifeT) { A.p -= e.amount; A.p /= 2; }\n"
    "  A.update(REAL globalT, REAL localT, REAL lifeT, REAL dt) { p = localT; v = vec3(1, 2, "
    "3); }\n"
    "}"));
  const auto& rs = m.instance("K")->reactions;
  ASSERT_EQ(rs.size(), 6u);
  EXPECT_EQ(rs[5].cell.text, "A");
  EXPECT_EQ(rs[2].body[0]->op, "+=");
  EXPECT_EQ(rs[3].body[0]->op, "*=");
  EXPECT_EQ(rs[4].body[0]->op, "-=");
  EXPECT_EQ(rs[4].body[1]->op, "/=");
}

TEST(IcmConstructs, ImperativeCore)
{
  const IcmModel m = ok(inUpdate("real r = 1.5; int n = 3; bool b = !flag && r < 2.0;\n"
                                 "vec3 w = vec3(r, 0, 0) * 2; string s = \"label\";\n"
                                 "for i in 0..n { r += i; if (i == 2) { b = true; } }\n"
                                 "for j in 0..intersectionCount(A, B) { w.x = j; }\n"
                                 "if (b || r >= 3) { A.p = r; } else if (n != 0) { A.p = -r; }"
                                 " else { A.p = 0; }\n"
                                 "{ real inner = distance(A, B); A.p = inner; }\n"
                                 "if (intersects(A, B)) fireEvent(E, 2.0);\n"
                                 "fireEvent(TIME_REJECTED, -0.01);\n"
                                 "A.v = vec3(w.x, length(w), dot(w, w));\n"
                                 "r = max(min(r, 1), abs(-r)) + sqrt(pow(r, 2)) + pi;"));
  const auto& body = m.instance("K")->reactions[0].body;
  ASSERT_EQ(body.size(), 13u);
  EXPECT_EQ(body[0]->kind, icm::Stmt::Kind::Local);
  EXPECT_EQ(body[5]->kind, icm::Stmt::Kind::For);
  EXPECT_EQ(body[5]->name, "i");
  EXPECT_EQ(body[7]->kind, icm::Stmt::Kind::If);
  EXPECT_EQ(body[7]->elseBody[0]->kind, icm::Stmt::Kind::If);
  EXPECT_EQ(body[8]->kind, icm::Stmt::Kind::Block);
  EXPECT_EQ(body[10]->kind, icm::Stmt::Kind::Eval);
  EXPECT_EQ(body[10]->value->text, "fireEvent");
}

TEST(IcmConstructs, PredicateAndFunctions)
{
  const IcmModel m = ok(withCells("PREDICATE { bool evaluate(REAL globalT, REAL localT, REAL dt)"
                                  " { if (globalT > 1) { return false; } return !flag; } }",
    "function ramp(real t, real k) { real r = t * k; return r; }\n"
    "function twice(real t) { return 2 * ramp(t, 1); }\n"));
  ASSERT_EQ(m.functions.size(), 2u);
  EXPECT_EQ(m.functions[0].formals.size(), 2u);
  EXPECT_EQ(m.instance("K")->predicates[0].resultType, "bool");
  // A function is called like a built-in.
  const IcmModel f = ok(withCells("REACTIONS { update(REAL globalT, REAL localT, REAL lifeT, REAL "
                                  "dt) { A.p = ramp(localT, 2); } }",
    "function ramp(real t, real k) { return t * k; }\n"));
  EXPECT_EQ(f.instance("K")->reactions[0].body[0]->value->text, "ramp");
}

// ---- diagnostics (line and column asserted) -----------------------------------------------------

namespace
{
struct Case
{
  const char* name;
  std::string text;
  const char* expected; ///< "line:col: error: message start"
};
} // namespace

TEST(IcmDiagnostics, LineColumnAndMessage)
{
  const std::string header = "CELLS { A { parameters { p : REAL(0); } } B { } }\n"; // line 1
  const std::string t = "T : TEMPLATE_IC { CELLS { A B; } }\n";                     // line 2
  const std::vector<Case> cases = {
    { "syntax", "CELLS { A { type = ; } }", "1:20: error: expected an expression, found ';'" },
    { "unclosed", "CELLS {\n A {\n", "2:4: error: '{' of cell A is never closed" },
    { "undefined cell in instance", header + "K { CELLS { A C; } }",
      "2:15: error: undefined cell 'C'" },
    { "undefined source", "CELLS { A <- Z { } }", "1:14: error: undefined cell 'Z' after '<-'" },
    { "duplicate cell", "CELLS { A { } }\nCELLS { A { } }",
      "2:9: error: duplicate cell 'A' (first defined at line 1)" },
    { "duplicate event", "EVENTS { E { } E { } }",
      "1:16: error: duplicate event 'E' (first defined at line 1)" },
    { "duplicate timespan", "TIMESPANS { s : TIMESPAN; s : TIMESPAN; }",
      "1:27: error: duplicate time span 's'" },
    { "undefined timespan", "CELLS { A { timespan = never; } }",
      "1:24: error: undefined time span 'never'" },
    { "undefined template", header + "K : U { }", "2:5: error: undefined template 'U'" },
    { "use unknown", header + "K { CELLS { USE NOPE.CELLS; } }",
      "2:17: error: undefined template or instance 'NOPE'" },
    { "use wrong section", header + t + "K { RELATIONS { dependency { USE T.CELLS; } } }",
      "3:34: error: expected USE T.RELATIONS.dependency, found T.CELLS" },
    { "exclude unknown", header + t + "K { CELLS { USE T.CELLS \\ { Q }; } }",
      "3:29: error: 'Q' is not a cell of T" },
    { "relation arity", header + t + "K : T { RELATIONS { dependency { A.p; } } }",
      "3:34: error: a dependency needs a master and a slave" },
    { "relation arity topo", header + t + "K : T { RELATIONS { containment { A B c d; } } }",
      "3:41: error: too many words in a containment relation" },
    { "priority not a number",
      header + t + "K : T { RELATIONS { dependency { A.p B.x high n; } } }",
      "3:42: error: the priority of a dependency must be a number or HIERARCHICAL, found 'high'" },
    { "priority string", header + t + "K : T { RELATIONS { dependency { A.p B.x \"2\"; } } }",
      "3:42: error: the priority of a dependency must be a number" },
    { "event priority", "EVENTS { E { priority = fast; } }",
      "1:25: error: the priority must be a number" },
    { "relation end undefined", header + t + "K : T { RELATIONS { dependency { A.p Q.x; } } }",
      "3:38: error: undefined cell 'Q' in a dependency" },
    { "unknown parameter", header + t + "K : T { RELATIONS { dependency { A.zz B.x; } } }",
      "3:36: error: cell 'A' has no parameter 'zz'" },
    { "unknown builtin",
      header + t +
        "K : T { REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { A.p = frobnicate(1); } } }",
      "3:69: error: unknown function 'frobnicate'" },
    { "argument count",
      header + t +
        "K : T { REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { A.p = distance(A); } } }",
      "3:69: error: 'distance' takes 2 argument(s) (distance(cellA, cellB)), found 1" },
    { "cell argument",
      header + t +
        "K : T { REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { A.p = distance(A, 2); } } "
        "}",
      "3:81: error: argument 2 of 'distance' is a cell name" },
    { "undefined event",
      header + t +
        "K : T { REACTIONS { update(REAL g, REAL l, REAL f, REAL dt) { fireEvent(BOOM); } } }",
      "3:73: error: undefined event 'BOOM'" },
    { "event arguments",
      "EVENTS { E { parameters { a : REAL(0); } } }\n" + header + t +
        "K : T { REACTIONS { init(REAL g) { fireEvent(E); } } }",
      "4:36: error: event 'E' has 1 parameter(s), fireEvent gives 0" },
    { "reaction arity", header + t + "K : T { REACTIONS { update(REAL g) { } } }",
      "3:21: error: 'update' takes 4 parameter(s)" },
    { "unknown reaction", header + t + "K : T { REACTIONS { onTick(REAL g) { } } }",
      "3:21: error: unknown reaction 'onTick'" },
    { "undefined name", header + t + "K : T { REACTIONS { init(REAL g) { A.p = q; } } }",
      "3:42: error: undefined name 'q'" },
    { "shape reads an undefined name", "CELLS { A { shape = disk(2 * q); } }",
      "1:30: error: undefined name 'q'" },
    { "shape argument type", "CELLS { A { shape = disk(true); } }",
      "1:26: error: argument 1 of 'disk' must be a number" },
    { "unknown step policy", "steps = sometimes;", "1:9: error: unknown step policy 'sometimes'" },
    { "shape local", header + t + "K : T { REACTIONS { init(REAL g) { SHAPES s = 1; } } }",
      "3:36: error: unknown type 'SHAPES': real, int, bool, vec3, string or shape" },
    { "assign to argument", header + t + "K : T { REACTIONS { init(REAL g) { g = 1; } } }",
      "3:36: error: cannot assign to the argument 'g'" },
    { "type mismatch", header + t + "K : T { REACTIONS { init(REAL g) { bool b = 1.5; } } }",
      "3:45: error: cannot initialise a bool with a real" },
    { "unknown type", header + t + "K : T { REACTIONS { init(REAL g) { matrix m = 1; } } }",
      "3:36: error: unknown type 'matrix'" },
    { "condition", header + t + "K : T { REACTIONS { init(REAL g) { if (g) { } } } }",
      "3:40: error: the condition is a real, not a bool" },
    { "loop var", header + t + "K : T { REACTIONS { init(REAL g) { for i in 0..3 { i = 1; } } } }",
      "3:52: error: cannot assign to the loop variable 'i'" },
    { "loop bound", header + t + "K : T { REACTIONS { init(REAL g) { for i in 0..1e9 { } } } }",
      "3:48: error: the loop runs more than 10000000 times" },
    { "method call", header + t + "K : T { REACTIONS { init(REAL g) { A.domain.f(B); } } }",
      "3:36: error: only built-in functions and model functions can be called" },
    { "predicate must return",
      header + t +
        "K : T { PREDICATE { bool evaluate(REAL a, REAL b, "
        "REAL c) { } } }",
      "3:21: error: the predicate must return a bool" },
    { "two predicates",
      header + t +
        "K : T { PREDICATE { bool evaluate(REAL a, REAL b, REAL c) "
        "{ return true; } } PREDICATE { bool evaluate(REAL a, REAL "
        "b, REAL c) { return true; } } }",
      "3:90: error: instance 'K' has more than one predicate" },
    { "cell type", "CELLS { A { type = X-CELL; } }",
      "1:20: error: type = P-CELL, F-CELL, C-CELL, B-CELL or T-CELL" },
    { "shape file", "CELLS { A { shape = file(\"a.vtp\"); } }",
      "1:26: error: file \"a.vtp\": the shape files are .hf, .xml, .obj, .off, .ply or .stl (save "
      "a .vtp surface as .ply or .stl, e.g. with ParaView)" },
    { "shape builtin", "CELLS { A { shape = torus(1, 2); } }",
      "1:21: error: unknown shape constructor 'torus'" },
    { "domain", "CELLS { A { domain = { 1, 0, 0, 1 }; } }",
      "1:24: error: the domain's minimum is above its maximum" },
    { "unknown property", "CELLS { A { colour = 1; } }", "1:13: error: unknown property 'colour'" },
    { "duplicate relation name",
      header + t + "K : T { RELATIONS { containment { A B r; } boundary { B A r; } } }",
      "3:59: error: duplicate relation 'r'" },
    { "stray brace", "}", "1:1: error: unmatched '}'" },
    { "bad char", "CELLS { A { } } $", "1:17: error: unexpected character '$'" },
    { "unterminated hyperfun", "CELLS { A { shape = hyperfun { a(x[3]) { ",
      "1:21: error: "
      "unterminated "
      "hyperfun block" },
    { "empty hyperfun", "CELLS { A { shape = hyperfun { }; } }",
      "1:13: error: empty hyperfun block" },
    { "timespan", "TIMESPANS { s : TIMESPAN(5, 1); }",
      "1:13: error: time span 's' ends before it starts" },
    { "recursion", "function f(real x) { return f(x); }",
      "1:29: error: function 'f' is called before its definition ends (no recursion)" },
    { "hyperfun error", "CELLS {\n  S { shape = hyperfun {\ns(x[3], a[1]) { s = 1 - q; }\n}; }\n}",
      "3:25: error: in the hyperfun shape: " },
    { "hyperfun error first line",
      "CELLS { S { shape = hyperfun { s(x[3], a[1]) { s = 1 - q; } "
      "}; } }",
      "1:56: error: in the hyperfun shape: unknown variable 'q'" },
    { "animation without keys", "ANIMATIONS { a { interpolation = linear; } }",
      "1:14: error: the animation 'a' has no keys" },
    { "animation key width", "ANIMATIONS { a { keys = { 0, 1 }, { 1, 2, 3, 4 }; } }",
      "1:35: error: every key of an animation has the same number of values" },
    { "animation interpolation", "ANIMATIONS { a { keys = { 0, 1 }; interpolation = cubic; } }",
      "1:35: error: unknown interpolation (step, linear, catmullrom or hermite)" },
    { "undefined animation",
      header + t + "K : T { REACTIONS { init(REAL g) { A.p = animationValue(\"walk\", g); } } }",
      "3:57: error: undefined animation \"walk\"" },
    { "cycle policy", "cycles = sometimes;", "1:10: error: unknown cycle policy 'sometimes'" },
    { "self dependency", header + t + "K : T { RELATIONS { dependency { A.p A.p; } } }",
      "3:34: error: 'A.p' cannot depend on itself" },
  };
  for (const Case& c : cases)
  {
    SCOPED_TRACE(c.name);
    const std::string e = errorsOf(c.text);
    EXPECT_NE(e.find(std::string("t.icm:") + c.expected), std::string::npos) << e;
  }
}

TEST(IcmDiagnostics, SourceLineAndCaret)
{
  const std::string e = errorsOf("CELLS {\n  A { dim = 5D; }\n}");
  // 5D is not a dimension literal: 5 then D.
  EXPECT_NE(e.find("t.icm:2:13: error: malformed number '5'\n  A { dim = 5D; }\n            ^"),
    std::string::npos)
    << e;
}

TEST(IcmDiagnostics, SeveralPerRun)
{
  try
  {
    readIcm("CELLS { A { type = Q; } B <- Z { } }\nK { CELLS { A C D; } }", "m.icm");
    FAIL();
  }
  catch (const ParseError& e)
  {
    ASSERT_GE(e.diagnostics().size(), 4u);
    EXPECT_EQ(e.diagnostics()[0].where.line, 1);
    EXPECT_EQ(e.diagnostics()[0].where.column, 20);
    EXPECT_EQ(e.diagnostics().back().where.line, 2);
  }
  // Syntax errors recover at the next item.
  try
  {
    readIcm(
      "CELLS { A { type = ; dim = ; } B { x = = 1; } }\nEVENTS { E { priority = ; } }", "m.icm");
    FAIL();
  }
  catch (const ParseError& e)
  {
    ASSERT_EQ(e.diagnostics().size(), 4u);
    EXPECT_EQ(e.diagnostics()[3].where.line, 2);
  }
}

// ---- limits and robustness ---------------------------------------------------------------------

TEST(IcmLimits, NestingSizeAndGarbage)
{
  Limits limits;
  limits.maxNesting = 50;
  std::string deep = inUpdate("A.p = " + std::string(200, '(') + "1" + std::string(200, ')') + ";");
  try
  {
    readIcm(deep, "d.icm", limits);
    FAIL();
  }
  catch (const ParseError& e)
  {
    EXPECT_NE(std::string(e.what()).find("nesting too deep"), std::string::npos) << e.what();
  }
  std::string chain = "A.p = 1";
  for (int i = 0; i < 5000; ++i)
  {
    chain += " + 1";
  }
  try
  {
    readIcm(inUpdate(chain + ";"), "c.icm", limits);
    FAIL();
  }
  catch (const ParseError& e)
  {
    EXPECT_NE(std::string(e.what()).find("expression too long"), std::string::npos);
  }
  limits = Limits{};
  limits.maxSyntaxNodes = 1000;
  std::string many = "CELLS {";
  for (int i = 0; i < 2000; ++i)
  {
    many += " A" + std::to_string(i) + " { }";
  }
  many += " }";
  try
  {
    readIcm(many, "m.icm", limits);
    FAIL();
  }
  catch (const ParseError& e)
  {
    EXPECT_NE(std::string(e.what()).find("too large"), std::string::npos);
  }
  // USE chains that double at every step stay linear (the closures are memoised), and cycles
  // of USE or '<-' end.
  std::string doubling =
    "CELLS { C0 { } C1 <- C2 { } C2 <- C1 { } }\nI0 : TEMPLATE_IC { CELLS { C0; } }\n";
  for (int i = 1; i < 200; ++i)
  {
    const std::string prev = "I" + std::to_string(i - 1);
    doubling += "I" + std::to_string(i) + " : TEMPLATE_IC { CELLS { USE " + prev + ".CELLS; USE " +
      prev + ".CELLS; } }\n";
  }
  EXPECT_NE(
    errorsOf(doubling).find("t.icm:1:22: error: cell 'C1' is a copy of itself"), std::string::npos);
  doubling += "X : TEMPLATE_IC { CELLS { USE Y.CELLS; } }\nY : TEMPLATE_IC { CELLS { USE X.CELLS; "
              "} }\n";
  const std::string cycles = errorsOf(doubling);
  EXPECT_NE(cycles.find("t.icm:202:31: error: USE cycle: 'Y' takes from 'X'"), std::string::npos)
    << cycles;
  limits = Limits{};
  limits.maxFileBytes = 10;
  EXPECT_THROW(readIcm("CELLS { A { } }", "f.icm", limits), ParseError);
  EXPECT_THROW(readIcmFile("/nonexistent/x.icm"), ParseError);
  // Random bytes and mutated models: a model or a ParseError, nothing else.
  std::mt19937 rng(7);
  const std::string base = slurp(models / "andyhausen.icm");
  for (int round = 0; round < 300; ++round)
  {
    std::string s = base;
    const int edits = 1 + static_cast<int>(rng() % 8);
    for (int k = 0; k < edits; ++k)
    {
      const std::size_t at = rng() % s.size();
      switch (rng() % 3)
      {
        case 0:
          s.erase(at, 1 + rng() % 20);
          break;
        case 1:
          s.insert(at, 1, "{}();.,:\\<-=+\"x1 ."[rng() % 18]);
          break;
        default:
          s[at] = static_cast<char>(rng() % 256);
      }
    }
    try
    {
      readIcm(s, "r.icm");
      parseIcmNotation(s, "r.icm");
    }
    catch (const ParseError&)
    {
    }
  }
}
