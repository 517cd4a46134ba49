#!/usr/bin/env python3
"""Reads a VTU packing export with VTK's own reader and checks what ParaView would see.

usage: check_vtu.py <file.vtu> <expected_points> <expected_lines> <expected_first_radius>

Checks: point and cell counts (one vertex per particle, then one line per contact), the
cell types, the "radius" (Float64) and "contacts" (Int32) point arrays, the "kind" cell
array (0 particle, 1 contact), and the first radius exactly (the file is written with
%.17g). Exits 0 if all hold, 1 with a message per failed check otherwise, 2 if VTK is
missing (Debian: apt-get install python3-vtk9).
"""

import sys


def main(argv):
    if len(argv) != 5:
        print(__doc__, file=sys.stderr)
        return 2
    path = argv[1]
    expected_points = int(argv[2])
    expected_lines = int(argv[3])
    expected_first_radius = float(argv[4])
    try:
        import vtk
    except ImportError:
        print("check_vtu: cannot import vtk; install python3-vtk9", file=sys.stderr)
        return 2

    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    problems = []

    def expect(condition, message):
        if not condition:
            problems.append(message)

    points = grid.GetNumberOfPoints()
    cells = grid.GetNumberOfCells()
    expect(points == expected_points, f"{points} points, expected {expected_points}")
    expect(cells == expected_points + expected_lines,
           f"{cells} cells, expected {expected_points + expected_lines}")
    vertex_cells = sum(1 for c in range(cells) if grid.GetCellType(c) == vtk.VTK_VERTEX)
    line_cells = sum(1 for c in range(cells) if grid.GetCellType(c) == vtk.VTK_LINE)
    expect(vertex_cells == expected_points,
           f"{vertex_cells} VTK_VERTEX cells, expected {expected_points}")
    expect(line_cells == expected_lines, f"{line_cells} VTK_LINE cells, expected {expected_lines}")
    for c in range(min(cells, expected_points)):
        cell = grid.GetCell(c)
        if cell.GetCellType() != vtk.VTK_VERTEX or cell.GetPointId(0) != c:
            problems.append(f"cell {c} is not the vertex of point {c}")
            break

    point_data = grid.GetPointData()
    radius = point_data.GetArray("radius")
    contacts = point_data.GetArray("contacts")
    expect(radius is not None, "no point array 'radius'")
    expect(contacts is not None, "no point array 'contacts'")
    if radius is not None:
        expect(radius.GetDataType() == vtk.VTK_DOUBLE, "'radius' is not Float64")
        expect(radius.GetNumberOfTuples() == points, "'radius' does not have one value per point")
        if points > 0:
            first = radius.GetValue(0)
            expect(first == expected_first_radius,
                   f"first radius {first!r}, expected {expected_first_radius!r}")
            expect(all(radius.GetValue(i) > 0 for i in range(points)), "a radius is <= 0")
    if contacts is not None:
        expect(contacts.GetDataType() == vtk.VTK_INT, "'contacts' is not Int32")
        total = sum(contacts.GetValue(i) for i in range(contacts.GetNumberOfTuples()))
        expect(total == 2 * expected_lines,
               f"contact counts sum to {total}, expected twice the lines, {2 * expected_lines}")

    kind = grid.GetCellData().GetArray("kind")
    expect(kind is not None, "no cell array 'kind'")
    if kind is not None:
        for c in range(cells):
            wanted = 0 if grid.GetCellType(c) == vtk.VTK_VERTEX else 1
            if kind.GetValue(c) != wanted:
                problems.append(f"cell {c}: kind {kind.GetValue(c)}, expected {wanted}")
                break

    for problem in problems:
        print(f"check_vtu: {path}: {problem}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
