// VTK 9 XML PolyData writer. VTK headers stay in this file.
#include "debugtools/vtk_export.h"

#include "core/error.h"
#include "core/image_io.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkFieldData.h>
#include <vtkFloatArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkStringArray.h>
#include <vtkXMLPolyDataWriter.h>

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

}  // namespace pathlab
