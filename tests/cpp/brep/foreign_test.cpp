// Foreign geometry in a child process: valid inputs read as before, damaged ones end as named
// errors (a crash, a cut-short text, a hang, a huge allocation), and OCCT's failures in words.
#include "brep/foreign.h"

#include <gtest/gtest.h>
#include <BRepGProp.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <OSD.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_NullObject.hxx>
#include <Standard_OutOfRange.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>

#include <chrono>
#include <csignal>
#include <fstream>
#include <sstream>
#include <thread>

#include "brep/occt_guard.h"
#include "brep/shape_io.h"
#include "brep/two_breps.h"
#include "common/error.h"
#include "common/isolate.h"

using namespace topopt;
using namespace topopt::brep;

namespace {

std::string text_of(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

std::string hostile(const std::string& name) { return std::string(TOPOPT_TEST_DATA) + "/hostile/" + name; }

/// The error `work` throws (fails the test when it throws none).
Error error_of(const std::function<void()>& work) {
  try {
    work();
  } catch (const Error& e) {
    return e;
  }
  ADD_FAILURE() << "no error";
  return Error(ErrorCode::Internal, "");
}

bool has(const Error& e, const std::string& words) { return std::string(e.what()).find(words) != std::string::npos; }

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int face_count(const TopoDS_Shape& s) {
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(s, TopAbs_FACE, faces);
  return faces.Extent();
}

double volume(const TopoDS_Shape& s) {
  GProp_GProps props;
  BRepGProp::VolumeProperties(s, props);
  return props.Mass();
}

}  // namespace

TEST(ForeignRead, ValidFilesReadExactlyAsOcctReadsThemInProcess) {
  for (const char* name : {"examples/rocker.step", "nist/NIST_MBE_PMI_1.stp", "occt/CrankArm.brep"}) {
    const std::string path = std::string(TOPOPT_SHARED_DATA) + "/" + name;
    TopoDS_Shape direct;
    if (std::string(name).find(".brep") != std::string::npos) {
      BRep_Builder b;
      ASSERT_TRUE(BRepTools::Read(direct, path.c_str(), b));
    } else {
      STEPControl_Reader r;
      ASSERT_EQ(r.ReadFile(path.c_str()), IFSelect_RetDone);
      r.TransferRoots();
      direct = r.OneShape();
    }
    const TopoDS_Shape isolated = read_shape_file(path, "part");
    EXPECT_EQ(face_count(isolated), face_count(direct)) << name;
    EXPECT_NEAR(volume(isolated), volume(direct), 1e-9 * std::abs(volume(direct))) << name;
    // the same faces in the same order (FreeCAD's FaceN numbering): same areas one by one
    TopTools_IndexedMapOfShape a, b;
    TopExp::MapShapes(isolated, TopAbs_FACE, a);
    TopExp::MapShapes(direct, TopAbs_FACE, b);
    for (int f = 1; f <= a.Extent() && f <= b.Extent(); ++f) {
      GProp_GProps pa, pb;
      BRepGProp::SurfaceProperties(a(f), pa);
      BRepGProp::SurfaceProperties(b(f), pb);
      ASSERT_NEAR(pa.Mass(), pb.Mass(), 1e-9 * pb.Mass()) << name << " Face" << f;
    }
    // every edge range and vertex exactly as read (OCCT's BREP text would round them to 15
    // digits, enough to change a mesh)
    TopTools_IndexedMapOfShape ea, eb, va, vb;
    TopExp::MapShapes(isolated, TopAbs_EDGE, ea);
    TopExp::MapShapes(direct, TopAbs_EDGE, eb);
    ASSERT_EQ(ea.Extent(), eb.Extent());
    for (int e = 1; e <= ea.Extent(); ++e) {
      double a0, a1, b0, b1;
      BRep_Tool::Range(TopoDS::Edge(ea(e)), a0, a1);
      BRep_Tool::Range(TopoDS::Edge(eb(e)), b0, b1);
      ASSERT_TRUE(a0 == b0 && a1 == b1) << name << " Edge" << e;
    }
    TopExp::MapShapes(isolated, TopAbs_VERTEX, va);
    TopExp::MapShapes(direct, TopAbs_VERTEX, vb);
    for (int v = 1; v <= va.Extent(); ++v)
      ASSERT_EQ(BRep_Tool::Pnt(TopoDS::Vertex(va(v))).Distance(BRep_Tool::Pnt(TopoDS::Vertex(vb(v)))), 0.0)
          << name << " Vertex" << v;
  }
}

TEST(ForeignRead, TriangulationsAndEveryOtherSectionReadThroughTheThrowingStream) {
  // a shape carrying triangulations (as FreeCAD's display leaves them) and a location
  TopoDS_Shape box = BRepPrimAPI_MakeBox(gp_Pnt(1, 2, 3), 4, 5, 6).Shape();
  BRepMesh_IncrementalMesh(box, 0.5);
  const TopoDS_Shape back = read_brep_string(write_brep_string(box), "part");
  EXPECT_NEAR(volume(back), 120.0, 1e-9);
  int triangulated = 0;
  for (TopExp_Explorer ex(back, TopAbs_FACE); ex.More(); ex.Next()) {
    TopLoc_Location loc;
    triangulated += !BRep_Tool::Triangulation(TopoDS::Face(ex.Current()), loc).IsNull();
  }
  EXPECT_EQ(triangulated, 6);
}

TEST(ForeignRead, PlainStreamSpinsOnCutShortTextTheThrowingOneStopsAtTheLine) {
  // Why BRepTools::Read hangs: on a stream in fail state `>>` leaves its variable as it was,
  // and the loop over a vertex's point representations, `do { IS >> n; ... } while (n > 0)`,
  // never ends. This cut ends inside a vertex record.
  const std::string full =
      write_brep_string(read_shape_file(std::string(TOPOPT_SHARED_DATA) + "/examples/rocker.step"));
  const size_t cut = full.find("\nVe\n", full.size() / 2) + 14;
  const std::string text = full.substr(0, cut);
  const Error spin = error_of([&] {
    run_isolated("the plain stream", 2, [&] {
      std::istringstream in(text);
      TopoDS_Shape s;
      BRep_Builder b;
      BRepTools::Read(s, in, b);
      return std::string();
    });
  });
  EXPECT_EQ(spin.code(), ErrorCode::Timeout) << spin.what();
  const auto t0 = std::chrono::steady_clock::now();
  const Error e = error_of([&] { read_brep_string(text, "part"); });
  EXPECT_LT(seconds_since(t0), 2.0);
  EXPECT_EQ(e.code(), ErrorCode::Io);
  const long lines = std::count(text.begin(), text.end(), '\n') + 1;
  EXPECT_TRUE(has(e, "the part (its BREP text) is damaged or cut short: reading it failed at line " +
                         std::to_string(lines) + " of " + std::to_string(lines)))
      << e.what();
}

TEST(ForeignRead, PrecheckRefusesNonBrepAndTextWithoutShapes) {
  const Error garbage = error_of([] { read_brep_string("this is not a shape", "part"); });
  EXPECT_EQ(garbage.code(), ErrorCode::Io);
  EXPECT_TRUE(has(garbage, "the part (its BREP text) is not BREP text: it lacks the 'CASCADE Topology' header"))
      << garbage.what();
  const Error headless =
      error_of([] { read_brep_string("\nCASCADE Topology V3, (c) Open Cascade\nLocations 0\nCurve2ds 3\n", "part"); });
  EXPECT_TRUE(has(headless, "is cut short: its text ends before the list of shapes ('TShapes', line 5)"))
      << headless.what();
}

TEST(ForeignRead, CrashWhileReadingIsNamedWithAdvice) {
  const Error e = error_of([] { read_shape_file(hostile("line_missing_a_number.brep"), "part"); });
  EXPECT_EQ(e.code(), ErrorCode::Crashed) << e.what();
  EXPECT_TRUE(has(e, "the part's file '" + hostile("line_missing_a_number.brep") +
                         "' is damaged: OCCT crashed reading it (Segmentation fault, signal 11); re-export it from "
                         "your CAD system"))
      << e.what();
  const Error s =
      error_of([] { read_brep_string(text_of(hostile("line_missing_a_number.brep")), "non-design input"); });
  EXPECT_EQ(s.code(), ErrorCode::Crashed);
  EXPECT_TRUE(has(s, "the non-design input (its BREP text) is damaged: OCCT crashed reading it")) << s.what();
}

TEST(ForeignRead, HangCrashAndHugeAllocationInTheChildAreNamed) {
  const ForeignInput input{"the part's file 'p.step'", "re-export it from your CAD system", 1000};
  ForeignParams quick;
  quick.seconds = 0.5;
  const Error hang = error_of([&] {
    run_foreign(input, "reading", quick, [] {
      for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));
      return std::string();
    });
  });
  EXPECT_EQ(hang.code(), ErrorCode::Timeout);
  EXPECT_STREQ(hang.what(),
               "the part's file 'p.step' is damaged or very large: OCCT did not finish reading it within 0.5 s; "
               "re-export it from your CAD system, or allow more time (--time-budget) if it is large and sound");
  const Error crash = error_of([&] {
    run_foreign(input, "reading", {}, [] {
      std::raise(SIGSEGV);
      return std::string();
    });
  });
  EXPECT_EQ(crash.code(), ErrorCode::Crashed);
  EXPECT_STREQ(crash.what(),
               "the part's file 'p.step' is damaged: OCCT crashed reading it (Segmentation fault, signal 11); "
               "re-export it from your CAD system");
  ForeignParams small;
  small.memory_gb = 1;
  const Error alloc = error_of(
      [&] { run_foreign(input, "reading", small, [] { return std::string(size_t(3) << 30, 'x').substr(0, 1); }); });
  EXPECT_EQ(alloc.code(), ErrorCode::Io) << alloc.what();
  EXPECT_TRUE(
      has(alloc, "the part's file 'p.step' is damaged or too large: reading it needed more than 1 GB of memory"))
      << alloc.what();
  // an OCCT exception in the child: its kind in words, never its class or method name
  const Error occt = error_of([&] {
    run_foreign(input, "reading", {},
                []() -> std::string { throw Standard_OutOfRange("NCollection_IndexedMap::FindKey"); });
  });
  EXPECT_EQ(occt.code(), ErrorCode::Io);
  EXPECT_STREQ(occt.what(),
               "the part's file 'p.step' is damaged: OCCT could not finish reading it (an index out of range); "
               "re-export it from your CAD system");
}

TEST(ForeignRead, BudgetGrowsWithTheInputAndCanBeFixed) {
  ForeignParams p;
  EXPECT_DOUBLE_EQ(foreign_seconds(0, p), 30);
  EXPECT_DOUBLE_EQ(foreign_seconds(2 * 1024 * 1024, p), 60);
  p.seconds = 7;
  EXPECT_DOUBLE_EQ(foreign_seconds(2 * 1024 * 1024, p), 7);
  EXPECT_DOUBLE_EQ(shape_bytes(BRepPrimAPI_MakeBox(1, 1, 1).Shape()), 6 * 4096.0);
}

TEST(OcctGuard, FailuresInWordsWithoutOcctNames) {
  const Error e = error_of([] {
    guard_occt("classifying the non-design solids against the part",
               []() -> int { throw Standard_OutOfRange("NCollection_IndexedMap::FindKey"); });
  });
  EXPECT_EQ(e.code(), ErrorCode::InvalidShape);
  EXPECT_TRUE(has(e,
                  "classifying the non-design solids against the part failed inside the geometry kernel, OCCT "
                  "(an index out of range): check the part and the non-design solids"))
      << e.what();
  EXPECT_FALSE(has(e, "NCollection"));
  EXPECT_EQ(guard_occt("adding", [] { return 2 + 3; }), 5);
}

TEST(OcctGuard, AFailureOnTopOptsOwnShapeDoesNotBlameTheInputs) {
  // the result's STEP is built from TopOpt's own surface: re-exporting the part cannot help
  const Error e = error_of([] {
    guard_occt(
        "building result.step from the result surface",
        []() -> int { throw Standard_NullObject("BRep_Tool:: TopoDS_Vertex hasn't gp_Pnt"); }, OcctBlame::own_shape);
  });
  EXPECT_EQ(e.code(), ErrorCode::InvalidShape);
  EXPECT_TRUE(has(e, "building result.step from the result surface failed inside the geometry kernel, OCCT (a "
                     "missing curve, surface or shape): the fault is in the shape TopOpt made itself"))
      << e.what();
  EXPECT_FALSE(has(e, "re-export"));
  EXPECT_FALSE(has(e, "check the part"));
  EXPECT_FALSE(has(e, "BRep_Tool"));
}

TEST(OcctGuard, AccessViolationBecomesANamedErrorWhereOcctsHandlerIsSet) {
  // In a child, so that OCCT's handler is installed there only. With OSD::SetSignal (as the
  // CLI sets it) a null dereference inside guard_occt comes back as Error(Crashed) in words;
  // without it (FreeCAD) the same fault ends the process.
  auto null_read = [] {
    volatile int* p = nullptr;
    return *p;
  };
  const std::string answer = run_isolated("the deliberate access violation", 10, [&] {
    OSD::SetSignal(Standard_False);
    try {
      guard_occt("reading a null pointer", null_read);
    } catch (const Error& e) {
      return std::string(error_code_name(e.code())) + ": " + e.what();
    }
    return std::string("no error");
  });
  EXPECT_EQ(
      answer.rfind("Crashed: reading a null pointer failed inside the geometry kernel, OCCT (an access violation or "
                   "another fatal signal, caught)",
                   0),
      0u)
      << answer;
  const Error unguarded = error_of([&] {
    run_isolated("the unguarded access violation", 10, [&] {
      for (int sig : {SIGSEGV, SIGBUS}) std::signal(sig, SIG_DFL);
      guard_occt("reading a null pointer", null_read);
      return std::string("no error");
    });
  });
  EXPECT_EQ(unguarded.code(), ErrorCode::Crashed);
}
