// VTK 9 XML PolyData writer. VTK headers stay in this file.
#include "debugtools/vtk_export.h"

#include "core/error.h"
#include "core/image_io.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataWriter.h>

#include <fstream>
#include <string>

namespace pathlab {
namespace fs = std::filesystem;

namespace {

vtkNew<vtkFloatArray> float_array(const char* name, int components) {
  vtkNew<vtkFloatArray> a;
  a->SetName(name);
  a->SetNumberOfComponents(components);
  return a;
}

vtkNew<vtkIntArray> int_array(const char* name) {
  vtkNew<vtkIntArray> a;
  a->SetName(name);
  return a;
}

void write_poly(const fs::path& file, vtkPolyData* poly) {
  write_via_temp_file(file, "VTK file", [&](const fs::path& temp) {
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetFileName(temp.c_str());
    writer->SetInputData(poly);
    writer->SetDataModeToBinary();
    if (writer->Write() != 1 || writer->GetErrorCode() != 0)
      throw SystemError(file.string() + ": cannot write VTK file: the VTK XML writer failed (error code " +
                        std::to_string(writer->GetErrorCode()) + ")");
  });
}

}  // namespace

bool vtk_export_available() { return true; }

void write_path_vtp(const fs::path& file, std::span<const PathLine> lines) {
  ensure_writable(file);  // before the work: a bad path fails at once

  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  vtkNew<vtkCellArray> cells;
  auto depth = int_array("depth");
  auto throughput = float_array("throughput", 3);
  auto added = float_array("radiance_added", 3);
  auto pdf = float_array("pdf", 1);
  auto lobe = int_array("lobe");
  auto flags = int_array("flags");
  auto kind = int_array("kind");
  auto sample = int_array("sample");

  for (const PathLine& line : lines) {
    cells->InsertNextCell(static_cast<vtkIdType>(line.points.size()));
    for (const PathPoint& p : line.points) {
      cells->InsertCellPoint(points->InsertNextPoint(p.p.x, p.p.y, p.p.z));
      depth->InsertNextValue(p.depth);
      throughput->InsertNextTuple3(p.throughput.x, p.throughput.y, p.throughput.z);
      added->InsertNextTuple3(p.added.x, p.added.y, p.added.z);
      pdf->InsertNextValue(p.pdf);
      lobe->InsertNextValue(p.lobe);
      flags->InsertNextValue(static_cast<int>(p.flags));
    }
    kind->InsertNextValue(static_cast<int>(line.kind));
    sample->InsertNextValue(static_cast<int>(line.sample));
  }

  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->SetLines(cells);
  for (vtkDataArray* a : {static_cast<vtkDataArray*>(depth), static_cast<vtkDataArray*>(throughput),
                          static_cast<vtkDataArray*>(added), static_cast<vtkDataArray*>(pdf),
                          static_cast<vtkDataArray*>(lobe), static_cast<vtkDataArray*>(flags)})
    poly->GetPointData()->AddArray(a);
  poly->GetCellData()->AddArray(kind);
  poly->GetCellData()->AddArray(sample);
  // The meaning of `lobe`: lobe_names[i] names lobe i.
  vtkNew<vtkStringArray> lobe_names;
  lobe_names->SetName("lobe_names");
  for (int l = 0; l < static_cast<int>(Lobe::Count); ++l) lobe_names->InsertNextValue(lobe_name(static_cast<Lobe>(l)));
  poly->GetFieldData()->AddArray(lobe_names);

  write_poly(file, poly);
}

void write_geometry_vtp(const fs::path& file, const SceneGeometry& geometry) {
  ensure_writable(file);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  vtkNew<vtkCellArray> cells;
  auto shape = int_array("shape");
  auto material = int_array("material");
  auto hits = int_array("hits");
  vtkNew<vtkIdTypeArray> prim, instance;  // 64-bit: a mesh may have more than 2^31 triangles
  prim->SetName("prim");
  instance->SetName("instance");
  for (const GeometryTriangle& t : geometry.triangles) {
    cells->InsertNextCell(3);
    for (const vec3& p : t.p) cells->InsertCellPoint(points->InsertNextPoint(p.x, p.y, p.z));
    shape->InsertNextValue(static_cast<int>(t.shape));
    material->InsertNextValue(static_cast<int>(t.material));
    hits->InsertNextValue(static_cast<int>(t.hits));
    prim->InsertNextValue(static_cast<vtkIdType>(t.prim));
    instance->InsertNextValue(static_cast<vtkIdType>(t.instance));
  }
  vtkNew<vtkPolyData> poly;
  poly->SetPoints(points);
  poly->SetPolys(cells);
  for (vtkDataArray* a : {static_cast<vtkDataArray*>(shape), static_cast<vtkDataArray*>(prim),
                          static_cast<vtkDataArray*>(instance), static_cast<vtkDataArray*>(material),
                          static_cast<vtkDataArray*>(hits)})
    poly->GetCellData()->AddArray(a);
  const auto field = [&](const char* name, vtkIdType value) {
    vtkNew<vtkIdTypeArray> a;
    a->SetName(name);
    a->InsertNextValue(value);
    poly->GetFieldData()->AddArray(a);
  };
  field("scene_triangles", static_cast<vtkIdType>(geometry.scene_triangles));
  field("limit", static_cast<vtkIdType>(geometry.limit));
  field("complete", geometry.complete ? 1 : 0);
  vtkNew<vtkStringArray> scope;
  scope->SetName("scope");
  scope->InsertNextValue(geometry.asked == GeometryScope::Scene ? "scene" : "hit");
  poly->GetFieldData()->AddArray(scope);
  write_poly(file, poly);
}

fs::path geometry_vtp_path(const fs::path& vtp) { return fs::path(vtp).replace_extension(".geometry.vtp"); }
fs::path multiblock_path(const fs::path& vtp) { return fs::path(vtp).replace_extension(".vtm"); }

void write_paths_and_geometry(const fs::path& vtp, std::span<const PathLine> lines, const SceneGeometry& geometry) {
  const fs::path geo = geometry_vtp_path(vtp), vtm = multiblock_path(vtp);
  ensure_writable(vtm);
  write_path_vtp(vtp, lines);
  write_geometry_vtp(geo, geometry);
  // The XML multiblock format of VTK 9 (what vtkXMLMultiBlockDataWriter
  // writes), with our two files as its blocks.
  const auto xml = [](const std::string& text) {  // a file name as an XML attribute value
    std::string o;
    for (char c : text) {
      if (c == '&') o += "&amp;";
      else if (c == '"') o += "&quot;";
      else if (c == '<') o += "&lt;";
      else if (c == '>') o += "&gt;";
      else o += c;
    }
    return o;
  };
  write_via_temp_file(vtm, "VTK multiblock file", [&](const fs::path& temp) {
    std::ofstream out(temp);
    out << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"vtkMultiBlockDataSet\" version=\"1.0\" byte_order=\"LittleEndian\">\n"
        << "  <vtkMultiBlockDataSet>\n"
        << "    <DataSet index=\"0\" name=\"paths\" file=\"" << xml(vtp.filename().string()) << "\"/>\n"
        << "    <DataSet index=\"1\" name=\"geometry\" file=\"" << xml(geo.filename().string()) << "\"/>\n"
        << "  </vtkMultiBlockDataSet>\n"
        << "</VTKFile>\n";
    out.close();
    if (!out) throw SystemError(vtm.string() + ": cannot write VTK multiblock file");
  });
}

}  // namespace pathlab
