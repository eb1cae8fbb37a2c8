// Regions and their materials as the mesh formats carry them (issue 25): Vega *MATERIAL / *SET /
// *REGION, Gmsh physical groups, TetGen region attributes; and the materials a user sets by region
// name. Mistakes are refused with the file and line, or the region's name.
#include "core/material/region_materials.hpp"
#include "core/mesh/mesh_io.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace tissue {
namespace {

// Two tets sharing the face (1, 2, 3), one each side.
const std::string VEG_VERTICES =
    "*VERTICES\n5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n"
    "*ELEMENTS\nTET\n2 4 0\n1 1 2 3 4\n2 2 5 3 4\n";

std::string message_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const std::exception& error) {
    return error.what();
  }
  return "(nothing thrown)";
}

TEST(VegRegions, EachRegionIsNamedByItsSetAndHasItsMaterial) {
  const TetMesh mesh = parse_veg(VEG_VERTICES +
                                     "*MATERIAL soft\nENU, 1000, 1e5, 0.4\n"
                                     "*MATERIAL stiff\nENU, 1100, 1e6, 0.45\n"
                                     "*SET skin\n1\n*SET tumour\n2,\n"
                                     "*REGION\nskin, soft\ntumour, stiff\n",
                                 "two.veg");
  ASSERT_EQ(mesh.regions.size(), 2u);
  EXPECT_EQ(mesh.regions[0].name, "skin");
  EXPECT_EQ(mesh.regions[1].name, "tumour");
  ASSERT_TRUE(mesh.regions[1].material.has_value());
  EXPECT_EQ(mesh.regions[1].material->young_modulus_pa, 1e6);
  EXPECT_EQ(mesh.regions[1].material->poisson_ratio, 0.45);
  EXPECT_EQ(mesh.regions[1].material->density_kg_per_m3, 1100.0);
  EXPECT_EQ(mesh.tet_regions, (std::vector<int>{0, 1}));
}

TEST(VegRegions, AllElementsIsPredefinedAndAFileWithoutRegionsHasNone) {
  const TetMesh one =
      parse_veg(VEG_VERTICES + "*MATERIAL body\nENU, 1000, 2e5, 0.3\n*REGION\nallElements, body\n", "a.veg");
  ASSERT_EQ(one.regions.size(), 1u);
  EXPECT_EQ(one.regions[0].name, "allElements");
  EXPECT_EQ(one.tet_regions, (std::vector<int>{0, 0}));
  MeshWarnings warnings;
  const TetMesh none = parse_veg(VEG_VERTICES + "*MATERIAL unused\nENU, 1000, 2e5, 0.3\n", "b.veg", &warnings);
  EXPECT_TRUE(none.regions.empty());
  EXPECT_TRUE(none.tet_regions.empty());
  ASSERT_EQ(warnings.messages.size(), 1u);
  EXPECT_EQ(warnings.messages[0], "b.veg:13: *MATERIAL unused is given to no *REGION: not used");
}

TEST(VegRegions, MistakesAreRefusedWithTheFileAndLine) {
  const std::string materials = "*MATERIAL soft\nENU, 1000, 1e5, 0.4\n*MATERIAL stiff\nENU, 1100, 1e6, 0.45\n";
  const auto refused = [&](const std::string& tail) {
    return message_of([&] { parse_veg(VEG_VERTICES + tail, "m.veg"); });
  };
  // Lines: 1-7 the vertices, 8-12 the elements, 13-16 the two materials.
  EXPECT_EQ(refused(materials + "*SET a\n1\n*REGION\nb, soft\n"), "m.veg:20: *REGION b, soft: no *SET named b");
  EXPECT_EQ(refused(materials + "*SET a\n1, 2\n*REGION\na, bone\n"),
            "m.veg:20: *REGION a, bone: no *MATERIAL named bone");
  EXPECT_EQ(refused(materials + "*SET a\n1, 2\n*SET b\n2\n*REGION\na, soft\nb, stiff\n"),
            "m.veg:23: *REGION b, stiff: element 2 is in two regions, a and b");
  EXPECT_EQ(refused(materials + "*SET a\n1\n*REGION\na, soft\n"),
            "m.veg:12: element 2: is in no region, while the file gives others regions (\"a\")");
  EXPECT_EQ(refused("*MATERIAL bad\nENU, 1000, 0, 0.4\n"),
            "m.veg:14: *MATERIAL bad: material: Young's modulus must be finite and > 0 Pa, got 0.000000");
  EXPECT_EQ(refused("*MATERIAL bad\nENU, 1000, 1e5, 0.5\n"),
            "m.veg:14: *MATERIAL bad: material: Poisson's ratio must be in [0, 0.5), got 0.500000");
  EXPECT_EQ(refused("*MATERIAL bad\nMOONEYRIVLIN, 1000, 1e5, 0.4\n"),
            "m.veg:14: *MATERIAL bad: material type 'MOONEYRIVLIN' is not supported (only ENU: density, E, nu)");
  EXPECT_EQ(refused(materials + "*SET a\n1, 7\n*REGION\na, soft\n"), "m.veg:17: *SET a: element 7 outside [1, 2]");
  EXPECT_EQ(refused(materials + "*MATERIAL soft\nENU, 1, 1, 0\n"),
            "m.veg:17: *MATERIAL soft: defined twice (first at line 13)");
}

// Two tets in two volumes (entity tags 1 and 2); `volume_groups` is the physical-tag part of the
// two volume lines of $Entities.
std::string gmsh_text(const std::string& physical_names, const std::string& volume_1_groups,
                      const std::string& volume_2_groups) {
  return "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n" + physical_names + "$Entities\n0 0 0 2\n1 0 0 0 1 1 1 " +
         volume_1_groups + " 0\n2 0 0 0 1 1 1 " + volume_2_groups +
         " 0\n$EndEntities\n"
         "$Nodes\n1 5 1 5\n3 1 0 5\n1\n2\n3\n4\n5\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n$EndNodes\n"
         "$Elements\n2 2 1 2\n3 1 4 1\n1 1 2 3 4\n3 2 4 1\n2 2 5 3 4\n$EndElements\n";
}

TEST(GmshRegions, PhysicalGroupsOfTheVolumesAreTheRegions) {
  const TetMesh named = parse_gmsh(
      gmsh_text("$PhysicalNames\n2\n3 7 \"liver tissue\"\n3 8 \"tumour\"\n$EndPhysicalNames\n", "1 7", "1 8"),
      "two.msh");
  ASSERT_EQ(named.regions.size(), 2u);
  EXPECT_EQ(named.regions[0].name, "liver tissue");
  EXPECT_EQ(named.regions[1].name, "tumour");
  EXPECT_FALSE(named.regions[0].material.has_value());
  EXPECT_EQ(named.tet_regions, (std::vector<int>{0, 1}));
  const TetMesh by_tag = parse_gmsh(gmsh_text("", "1 7", "1 7"), "one.msh");
  ASSERT_EQ(by_tag.regions.size(), 1u);
  EXPECT_EQ(by_tag.regions[0].name, "7");
  EXPECT_TRUE(parse_gmsh(gmsh_text("", "0", "0"), "none.msh").regions.empty());
}

TEST(GmshRegions, AVolumeInTwoGroupsOrInNoneIsRefused) {
  EXPECT_EQ(message_of([] { parse_gmsh(gmsh_text("", "2 7 8", "1 7"), "m.msh"); }),
            "m.msh:26: element 1: is in two regions, 7 and 8 (volume 1 is in both physical groups)");
  EXPECT_EQ(message_of([] { parse_gmsh(gmsh_text("", "1 7", "0"), "m.msh"); }),
            "m.msh:28: element 2: is in no region, while the file gives others regions (\"7\")");
}

TEST(TetgenRegions, TheFirstAttributeIsTheRegion) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "tissue_tetgen_regions";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "two.node") << "5 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n";
  std::ofstream(dir / "two.ele") << "2 4 1\n1 1 2 3 4 1\n2 2 5 3 4 2\n";
  const TetMesh mesh = read_tetgen(dir / "two.node");
  ASSERT_EQ(mesh.regions.size(), 2u);
  EXPECT_EQ(mesh.regions[0].name, "1");
  EXPECT_EQ(mesh.regions[1].name, "2");
  EXPECT_EQ(mesh.tet_regions, (std::vector<int>{0, 1}));
  std::ofstream(dir / "two.ele") << "2 4 1\n1 1 2 3 4 1\n2 2 5 3 4 2.5\n";
  EXPECT_NE(message_of([&] {
              read_tetgen(dir / "two.node");
            }).find("two.ele:3: element 2: region attribute 2.5 is not a whole number"),
            std::string::npos);
}

TEST(RegionMaterials, SetByNameReplacesTheFilesAndTheRestKeepTheirs) {
  const Material body{1e5, 0.4, 1000.0};
  const std::vector<MeshRegion> regions{
      {"skin", std::nullopt}, {"tumour", Material{1e6, 0.45, 1100.0}}, {"fat", std::nullopt}};
  const std::vector<Material> resolved =
      resolve_region_materials(regions, body, parse_region_materials("fat: youngModulus=3e4, density=900", body));
  ASSERT_EQ(resolved.size(), 3u);
  EXPECT_EQ(resolved[0].young_modulus_pa, 1e5);  // none anywhere: the body's
  EXPECT_EQ(resolved[1].young_modulus_pa, 1e6);  // the file's
  EXPECT_EQ(resolved[2].young_modulus_pa, 3e4);  // set by name, the keys left out the body's
  EXPECT_EQ(resolved[2].poisson_ratio, 0.4);
  EXPECT_EQ(resolved[2].density_kg_per_m3, 900.0);
  EXPECT_EQ(resolve_region_materials({}, body, {}).size(), 1u);
}

TEST(RegionMaterials, TheTextFormRoundTripsAndMistakesNameTheRegion) {
  const Material body{1e5, 0.4, 1000.0};
  const std::vector<RegionMaterial> parsed = parse_region_materials(
      " tumour : youngModulus = 1e6 , poissonRatio=0.45; skin: density=1050, dampingAlpha=3 ;", body);
  ASSERT_EQ(parsed.size(), 2u);
  EXPECT_EQ(parsed[0].material.mass_damping_per_s, std::nullopt);  // not given: the body's damping.alpha
  EXPECT_EQ(parsed[1].material.mass_damping_per_s, 3.0);
  // A property not set is left out of the text.
  EXPECT_EQ(format_region_materials(parsed),
            "tumour: youngModulus=1e+06, poissonRatio=0.45, density=1000; skin: youngModulus=1e+05, "
            "poissonRatio=0.4, density=1050, dampingAlpha=3");
  const std::vector<RegionMaterial> again = parse_region_materials(format_region_materials(parsed), body);
  ASSERT_EQ(again.size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(again[k].region, parsed[k].region);
    EXPECT_EQ(again[k].material.young_modulus_pa, parsed[k].material.young_modulus_pa);
    EXPECT_EQ(again[k].material.poisson_ratio, parsed[k].material.poisson_ratio);
    EXPECT_EQ(again[k].material.density_kg_per_m3, parsed[k].material.density_kg_per_m3);
    EXPECT_EQ(again[k].material.mass_damping_per_s, parsed[k].material.mass_damping_per_s);
  }
  EXPECT_TRUE(parse_region_materials("  ", body).empty());
  EXPECT_TRUE(parse_region_materials("none", body).empty());
  const auto refused = [&](const std::string& text) { return message_of([&] { parse_region_materials(text, body); }); };
  EXPECT_EQ(refused("tumour youngModulus=1e6"),
            "material.regions: \"tumour youngModulus=1e6\": expected 'name: key=value, ...'");
  EXPECT_EQ(refused("tumour: stiffness=1e6"),
            "material.regions: \"tumour: stiffness=1e6\": unknown key \"stiffness\" (youngModulus [Pa], poissonRatio, "
            "density [kg/m^3], dampingAlpha [1/s])");
  EXPECT_EQ(refused("tumour: youngModulus=-5"),
            "material.regions: \"tumour: youngModulus=-5\": material: Young's modulus must be finite and > 0 Pa, got "
            "-5.000000");
  EXPECT_EQ(refused("tumour: poissonRatio=nan"),
            "material.regions: \"tumour: poissonRatio=nan\": poissonRatio: \"nan\" is not a finite number");
  EXPECT_EQ(refused("tumour: dampingAlpha=-1"),
            "material.regions: \"tumour: dampingAlpha=-1\": damping: mass damping alpha must be finite and >= 0 1/s, "
            "got -1.000000");
  EXPECT_EQ(refused("a: density=1; a: density=2"), "material.regions: region \"a\" given twice");
  const std::vector<MeshRegion> regions{{"skin", std::nullopt}, {"tumour", std::nullopt}};
  EXPECT_EQ(
      message_of([&] { resolve_region_materials(regions, body, parse_region_materials("liver: density=1", body)); }),
      "material set for region \"liver\", which the mesh does not have (its regions: \"skin\", \"tumour\")");
  EXPECT_EQ(message_of([&] { resolve_region_materials({}, body, parse_region_materials("liver: density=1", body)); }),
            "material set for region \"liver\", which the mesh does not have (it has no regions)");
}

}  // namespace
}  // namespace tissue
