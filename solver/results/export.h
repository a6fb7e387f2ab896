// Writers of solver results: the per-organ CSV every solver shares, the per-structure CSV
// and the one-line summary.
#pragma once

#include <ostream>
#include <span>
#include <string>

#include "solver/results/light.h"

namespace leaflux {

// A number for a CSV or a summary: nine significant digits, no trailing zeros.
std::string Number(double value);
// A CSV field: as it is, or in double quotes (quotes doubled) when it holds a comma, a quote
// or a line break.
std::string CsvQuoted(const std::string& text);

// One row per receiver and band, columns:
// organ,band,area_m2,irradiance_upper_wm2,irradiance_lower_wm2,absorbed_w,
// light_x,light_y,light_z,stderr_upper_wm2,stderr_lower_wm2,
// photon_irradiance_upper_umol_m2_s,photon_irradiance_lower_umol_m2_s,absorbed_umol_s
// (stderr columns empty when the solver gives none; photon columns, µmol m⁻² s⁻¹ and
// µmol s⁻¹, the W columns times the band's PhotonUmolPerJ, empty for a band with none).
void WriteLeafCsv(std::ostream& out, const Scene& scene, const FlatScene& flat,
                  const Solution& solution);
// Its parts: the header line, and one receiver's rows (`error` empty: no standard errors).
void WriteLeafCsvHeader(std::ostream& out);
void WriteLeafRows(std::ostream& out, const Scene& scene, const Receiver& receiver,
                   std::span<const BandLight> light, std::span<const BandError> error);

// One row per structure and band: node,name,type,organs,area_m2, then as above.
void WriteStructureCsv(std::ostream& out, const Scene& scene,
                       const std::vector<StructureLight>& structures);

// ASCII PLY of every triangle (world coordinates) with the light of band `band` on its
// receiver as face properties: irradiance_upper, irradiance_lower (W/m²) and receiver.
void WritePly(std::ostream& out, const FlatScene& flat, const Solution& solution, int band);

// "<solver>: <receivers> receivers × <bands> bands in <t> s (cpu <c> s), peak <m> MiB,
//  <rays> rays; <band>: incident … W, absorbed … W (… umol/s, for a band with a photon
//  factor), escaped … W, residual …%".
std::string Summary(const std::string& solver, const Scene& scene, const FlatScene& flat,
                    const Solution& solution);

}  // namespace leaflux
