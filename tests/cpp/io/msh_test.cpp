// MSH 4.1: our writer and reader agree, and Gmsh itself reads what we write.
#include "io/msh.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/error.h"
#include "io/vtu.h"
#include "mesh/core/structured_box.h"

namespace topopt::io {
namespace {
namespace fs = std::filesystem;

TetMesh sample() {
  mesh::StructuredBoxParams p;
  p.size = {4, 2, 2};
  p.cells = {4, 2, 2};
  p.nondesign = {{0, 0, 0, 1, 2, 2}, {3, 0, 0, 4, 2, 2}};
  return mesh::structured_box_mesh(p);
}

fs::path temp(const std::string& name) {
  return fs::temp_directory_path() / ("topopt_io_" + std::to_string(::getpid()) + "_" + name);
}

TEST(Msh, RoundTripKeepsEverything) {
  TetMesh m = sample();
  fs::path p = temp("rt.msh");
  write_msh(p.string(), m);
  TetMesh r = read_msh(p.string());
  EXPECT_EQ(r.V, m.V);
  ASSERT_EQ(r.T.rows(), m.T.rows());
  ASSERT_EQ(r.F.rows(), m.F.rows());
  // order may change (grouped by domain / face); compare as sets of tagged entities
  auto tets = [](const TetMesh& x) {
    std::vector<std::array<int, 5>> v;
    for (long t = 0; t < x.T.rows(); ++t) v.push_back({x.T(t, 0), x.T(t, 1), x.T(t, 2), x.T(t, 3), x.domain[t]});
    std::sort(v.begin(), v.end());
    return v;
  };
  auto tris = [](const TetMesh& x) {
    std::vector<std::array<int, 5>> v;
    for (long t = 0; t < x.F.rows(); ++t) v.push_back({x.F(t, 0), x.F(t, 1), x.F(t, 2), x.face[t], x.nd_face[t]});
    std::sort(v.begin(), v.end());
    return v;
  };
  EXPECT_EQ(tets(r), tets(m));
  EXPECT_EQ(tris(r), tris(m));
  fs::remove(p);
}

TEST(Msh, GmshReadsOurFile) {
  if (std::system("/usr/bin/python3 -c 'import gmsh' > /dev/null 2>&1") != 0) GTEST_SKIP() << "python3-gmsh missing";
  TetMesh m = sample();
  fs::path p = temp("gmsh.msh"), out = temp("gmsh.txt");
  write_msh(p.string(), m);
  std::string script =
      "import gmsh,sys\n"
      "gmsh.initialize(); gmsh.option.setNumber('General.Terminal',0); gmsh.open(sys.argv[1])\n"
      "t,_,_=gmsh.model.mesh.getElements(3); f,_,_=gmsh.model.mesh.getElements(2)\n"
      "n=sum(len(x) for x in gmsh.model.mesh.getElements(3)[1])\n"
      "k=sum(len(x) for x in gmsh.model.mesh.getElements(2)[1])\n"
      "g=gmsh.model.getPhysicalGroups()\n"
      "d1=len(gmsh.model.mesh.getNodesForPhysicalGroup(3,1)[0])\n"
      "open(sys.argv[2],'w').write('%d %d %d %d %s' % (n,k,len([x for x in g if "
      "x[0]==3]),d1,gmsh.model.getPhysicalName(2,100001)))\n";
  fs::path py = temp("check.py");
  std::ofstream(py) << script;
  std::string cmd = "/usr/bin/python3 " + py.string() + " " + p.string() + " " + out.string();
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::ifstream in(out);
  long n, k, vols, d1;
  std::string name;
  in >> n >> k >> vols >> d1 >> name;
  EXPECT_EQ(n, m.T.rows());
  EXPECT_EQ(k, m.F.rows());
  EXPECT_EQ(vols, 3);  // design + two non-design boxes
  EXPECT_GT(d1, 0);
  EXPECT_EQ(name, "NonDesign:Face1");
  if (!HasFailure()) fs::remove(p), fs::remove(out), fs::remove(py);
}

TEST(Msh, MalformedFilesAreReportedWithTheLine) {
  fs::path p = temp("bad.msh");
  std::ofstream(p) << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 2\n3 1 0 2\n1\n2\n0 0 zero\n";
  try {
    read_msh(p.string());
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Io);
    EXPECT_NE(std::string(e.what()).find(":9:"), std::string::npos) << e.what();
  }
  try {
    read_msh(temp("missing.msh").string());
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::Io);
  }
  fs::remove(p);
}

TEST(Msh, ErrorsNeverRepeatTheFilesText) {
  // mesh.file may name any readable file: its content must not come back in a message
  fs::path p = temp("plain.txt");
  for (const std::string text : {"root:x:0:0:secret-token\n", "$SecretSection-token\nmore\n",
                                 "$MeshFormat\nsecret-token 0 8\n$EndMeshFormat\n"}) {
    std::ofstream(p) << text;
    try {
      read_msh(p.string());
      ADD_FAILURE() << "no error for " << text;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::Io);
      EXPECT_EQ(std::string(e.what()).find("token"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("MSH"), std::string::npos) << e.what();
    }
  }
  fs::remove(p);
}

TEST(Vtu, IsWellFormedXmlWithTheFields) {
  TetMesh m = sample();
  fs::path p = temp("r.vtu");
  VtuField u{"displacement", 3, std::vector<double>(3 * m.V.rows(), 0.5)};
  VtuField d{"density", 1, std::vector<double>(m.T.rows(), 1.0)};
  write_vtu(p.string(), m, {u}, {d});
  std::string cmd =
      "/usr/bin/python3 -c \"import xml.etree.ElementTree as E,sys; r=E.parse(sys.argv[1]).getroot(); "
      "pc=r.find('UnstructuredGrid/Piece'); names=[a.get('Name') for a in r.iter('DataArray')]; "
      "sys.exit(0 if pc.get('NumberOfCells')=='" +
      std::to_string(m.T.rows()) + "' and 'density' in names and 'displacement' in names else 1)\" " + p.string();
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  fs::remove(p);
}

}  // namespace
}  // namespace topopt::io
