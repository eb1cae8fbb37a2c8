// The settings schema (core/tissue_settings_schema.hpp): each setting declared once and consistently,
// its one default shared by the products and the core's own default agreeing with it or saying why
// not, and its range refused with a message that names it.
#include "core/tissue_settings_schema.hpp"

#include "core/mesh/box_mesh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>

namespace tissue {
namespace {

TEST(SettingsSchema, NamesValueReferencesAndKeywordsAreUnique) {
  std::set<std::string_view> names, keywords;
  std::set<std::uint32_t> references;
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    EXPECT_TRUE(names.insert(setting.name).second) << setting.name;
    EXPECT_TRUE(references.insert(setting.value_reference).second) << setting.name;
    if (!setting.python_keyword.empty()) {
      EXPECT_TRUE(keywords.insert(setting.python_keyword).second) << setting.name;
      EXPECT_EQ(find_python_setting(setting.python_keyword), &setting);
    }
    EXPECT_NE(setting.member, nullptr) << setting.name;
    EXPECT_FALSE(setting.description.empty()) << setting.name;
    EXPECT_EQ(find_setting(setting.name), &setting);
  }
  EXPECT_EQ(find_setting("no.suchSetting"), nullptr);
}

TEST(SettingsSchema, EveryDefaultIsOfItsTypeAndInItsRange) {
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    EXPECT_NO_THROW(check_value(setting, start_value(setting))) << setting.name;
    if (setting.type == SettingType::enumeration) {
      EXPECT_LT(start_item(setting), setting.items.size()) << setting.name;
    }
  }
  // And they make a tissue.
  const TissueSettings settings = resolve_settings(default_parameters(), nullptr);
  EXPECT_NO_THROW(Tissue(make_box_mesh(2, 2, 2, 0.01), settings));
}

TEST(SettingsSchema, AValueReadsBackAsItWasSet) {
  TissueParameters parameters = default_parameters();
  set_value(*find_setting("tool.probeRadius"), parameters, SettingValue(0.002));
  set_value(*find_setting("integrator.linearSolver"), parameters, SettingValue(std::string("pcgCholesky")));
  set_value(*find_setting("gravity"), parameters, SettingValue(std::array<double, 3>{1.0, 2.0, 3.0}));
  set_value(*find_setting("integrator.threads"), parameters, SettingValue(std::int64_t{2}));
  EXPECT_EQ(parameters.settings.interaction.probe_radius_m, 0.002);
  EXPECT_EQ(parameters.settings.solver.kind, LinearSolverKind::pcg_cholesky);
  EXPECT_EQ(parameters.settings.body.gravity_m_per_s2, Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_EQ(parameters.settings.integrator.threads, 2);
  EXPECT_EQ(value_of(*find_setting("integrator.linearSolver"), parameters), SettingValue(std::string("pcgCholesky")));
  EXPECT_EQ(value_of(*find_setting("integrator.threads"), parameters), SettingValue(std::int64_t{2}));
}

// The core's own defaults (TissueSettings{}) serve its tests and benches; where one differs from the
// products' (the schema's start), the entry says why, and only there.
TEST(SettingsSchema, TheCoresDefaultsAgreeWithTheSchemaOrSayWhy) {
  TissueParameters core;  // TissueSettings{} inside
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    if (setting.scope != SettingScope::tissue) continue;
    const bool same = value_of(setting, core) == start_value(setting);
    EXPECT_EQ(same, setting.core_default_note.empty())
        << setting.name << ": core default " << to_text(value_of(setting, core)) << ", schema default " << setting.start
        << (same ? " (agree, yet a note says they differ)" : " (differ, and no note says why)");
  }
}

// A bound is refused just past it and accepted at it when inclusive, with the setting's name, range
// and unit in the message; NaN is refused everywhere.
TEST(SettingsSchema, RangesAreCheckedWhereTheyAreSet) {
  int bounds = 0;
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    if (setting.type != SettingType::real && setting.type != SettingType::integer) continue;
    const auto value = [&](double v) {
      return setting.type == SettingType::real ? SettingValue(v) : SettingValue(static_cast<std::int64_t>(v));
    };
    for (const auto& [bound, direction] : {std::pair{setting.min, -1.0}, std::pair{setting.max, 1.0}}) {
      if (!bound) continue;
      ++bounds;
      const double at = std::stod(std::string(bound->value));
      const double past =
          setting.type == SettingType::integer ? at + direction : at + direction * std::max(1e-9, std::abs(at) * 1e-6);
      TissueParameters parameters = default_parameters();
      try {
        set_value(setting, parameters, value(past));
        ADD_FAILURE() << setting.name << " = " << past << " was accepted";
      } catch (const ParameterError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find(std::string(setting.name)), std::string::npos) << message;
        EXPECT_NE(message.find(range_text(setting)), std::string::npos) << message;
      }
      if (bound->inclusive) {
        EXPECT_NO_THROW(set_value(setting, parameters, value(at))) << setting.name;
      } else {
        EXPECT_THROW(set_value(setting, parameters, value(at)), ParameterError) << setting.name;
      }
    }
    if (setting.type == SettingType::real) {
      TissueParameters parameters = default_parameters();
      EXPECT_THROW(set_value(setting, parameters, value(std::numeric_limits<double>::quiet_NaN())), ParameterError)
          << setting.name;
    }
  }
  EXPECT_GE(bounds, 20);
  TissueParameters parameters = default_parameters();
  EXPECT_THROW(set_value(*find_setting("gravity"), parameters, SettingValue(std::array<double, 3>{0.0, NAN, 0.0})),
               ParameterError);
  EXPECT_THROW(set_value(*find_setting("integrator.method"), parameters, SettingValue(std::string("rk4"))),
               ParameterError);
  EXPECT_THROW(set_value(*find_setting("tool.probeRadius"), parameters, SettingValue(true)), ParameterError);
}

// The core's check of a TissueSettings is the schema's range, named as the products name it.
// The parts keep range checks of their own (validate(Material), validate(SolverSettings), ...: the
// core's direct users and the regions' materials pass through them without the schema), so a range
// is written there and in the schema. The schema is the one users read: no part may refuse a value
// at the edge of the schema's range, inside it (a part looser than the schema is harmless: the
// schema's check comes first).
TEST(SettingsSchema, ThePartsOwnChecksAcceptEveryValueTheSchemaAccepts) {
  int edges = 0;
  for (const SettingInfo& setting : TISSUE_SETTINGS) {
    if (setting.scope != SettingScope::tissue) continue;
    if (setting.type != SettingType::real && setting.type != SettingType::integer) continue;
    for (const auto& [bound, toward] : {std::pair{setting.min, std::numeric_limits<double>::infinity()},
                                        std::pair{setting.max, -std::numeric_limits<double>::infinity()}}) {
      if (!bound) continue;
      const double edge = std::stod(std::string(bound->value));
      TissueParameters parameters = default_parameters();
      if (setting.type == SettingType::real) {
        set_value(setting, parameters, SettingValue(bound->inclusive ? edge : std::nextafter(edge, toward)));
      } else {
        const auto step = static_cast<std::int64_t>(toward > 0 ? 1 : -1);
        set_value(setting, parameters,
                  SettingValue(static_cast<std::int64_t>(edge) + (bound->inclusive ? 0 : step)));
      }
      EXPECT_NO_THROW(validate(parameters.settings))
          << setting.name << " at the edge of its range " << range_text(setting);
      ++edges;
    }
  }
  EXPECT_GT(edges, 20);
}

TEST(SettingsSchema, TheCoresValidationNamesTheSetting) {
  TissueSettings settings;
  settings.interaction.probe_radius_m = -0.001;
  try {
    validate(settings);
    FAIL() << "a negative probe radius was accepted";
  } catch (const ParameterError& error) {
    EXPECT_EQ(std::string(error.what()), "tool.probeRadius must be finite and >= 0 m, got -0.001");
  }
}

// The one vocabulary: the core parses and prints the names the schema's items give (the FMU's).
TEST(SettingsSchema, EnumerationsHaveOneVocabulary) {
  EXPECT_EQ(to_string(LinearSolverKind::pcg_cholesky), "pcgCholesky");
  EXPECT_EQ(parse_integrator_kind("backwardEuler"), IntegratorKind::backward_euler);
  EXPECT_EQ(parse_contact_stiffness_model("elementLocal"), ContactStiffnessModel::element_local);
  EXPECT_THROW((void)parse_linear_solver_kind("pcg-cholesky"), ParameterError);
  EXPECT_EQ(find_setting("integrator.linearSolver")->items.data(), LINEAR_SOLVER_NAMES.all().data());
}

}  // namespace
}  // namespace tissue
