//! WGS-84 Earth model: radii of curvature, normal gravity with height terms, Earth rate
//! and transport rate in the local NED navigation frame, geodetic ↔ ECEF.
//!
//! Sources: NIMA TR8350.2 (WGS-84, 3rd ed.) for the constants and Somigliana's formula;
//! P. D. Groves, *Principles of GNSS, Inertial, and Multisensor Integrated Navigation
//! Systems*, 2nd ed. (2013), §2.4.2 (radii, eqs. 2.105–2.106), §2.4.7 (gravity with height,
//! eq. 2.134), §5.4 (Earth and transport rates, eqs. 5.41–5.44).

use driftless_model::linalg::Vec3;

/// Semi-major axis a, m.
pub(crate) const A_M: f64 = 6_378_137.0;
/// Flattening f.
pub const F: f64 = 1.0 / 298.257_223_563;
/// Semi-minor axis b = a(1 − f), m.
pub(crate) const B_M: f64 = A_M * (1.0 - F);
/// First eccentricity squared e² = f(2 − f).
pub(crate) const E2: f64 = F * (2.0 - F);
/// Earth rotation rate ω_ie, rad/s.
pub const OMEGA_IE: f64 = 7.292_115_146_7e-5;
/// Earth gravitational constant GM, m³/s².
pub const GM: f64 = 3.986_004_418e14;
/// Normal gravity at the equator γ_e, m/s² (WGS-84).
pub(crate) const GAMMA_E: f64 = 9.780_325_335_9;
/// Somigliana constant k = (b·γ_p)/(a·γ_e) − 1 (WGS-84).
pub(crate) const SOMIGLIANA_K: f64 = 0.001_931_852_652_41;

/// Meridian (north–south) radius of curvature R_M(φ) = a(1 − e²)/(1 − e² sin²φ)^{3/2}.
pub fn meridian_radius_m(lat_rad: f64) -> f64 {
    let s = lat_rad.sin();
    let w = 1.0 - E2 * s * s;
    A_M * (1.0 - E2) / (w * w.sqrt())
}

/// Prime-vertical (east–west) radius of curvature R_N(φ) = a/√(1 − e² sin²φ).
pub fn prime_vertical_radius_m(lat_rad: f64) -> f64 {
    let s = lat_rad.sin();
    A_M / (1.0 - E2 * s * s).sqrt()
}

/// Normal gravity magnitude at geodetic latitude φ and ellipsoidal height h:
/// Somigliana γ0(φ) = γ_e(1 + k sin²φ)/√(1 − e² sin²φ), then
/// γ(φ, h) = γ0[1 − (2/a)(1 + f + m − 2f sin²φ)h + (3/a²)h²], m = ω²a²b/GM
/// (Groves eq. 2.134; valid for |h| of a few tens of km).
pub fn normal_gravity_m_s2(lat_rad: f64, height_m: f64) -> f64 {
    let s2 = lat_rad.sin().powi(2);
    let g0 = GAMMA_E * (1.0 + SOMIGLIANA_K * s2) / (1.0 - E2 * s2).sqrt();
    let m = OMEGA_IE * OMEGA_IE * A_M * A_M * B_M / GM;
    g0 * (1.0 - 2.0 / A_M * (1.0 + F + m - 2.0 * F * s2) * height_m
        + 3.0 / (A_M * A_M) * height_m * height_m)
}

/// Gravity vector in NED, m/s² (normal gravity along +down; deflection of the vertical
/// neglected).
pub fn gravity_ned(lat_rad: f64, height_m: f64) -> Vec3 {
    [0.0, 0.0, normal_gravity_m_s2(lat_rad, height_m)]
}

/// Earth rotation rate resolved in NED: ω_ie^n = ω(cos φ, 0, −sin φ).
pub(crate) fn earth_rate_ned(lat_rad: f64) -> Vec3 {
    [OMEGA_IE * lat_rad.cos(), 0.0, -OMEGA_IE * lat_rad.sin()]
}

/// Transport rate (rotation of NED relative to the Earth) in NED:
/// ω_en^n = (v_E/(R_N + h), −v_N/(R_M + h), −v_E tan φ/(R_N + h)).
pub(crate) fn transport_rate_ned(lat_rad: f64, height_m: f64, vel_ned_m_s: Vec3) -> Vec3 {
    let rm = meridian_radius_m(lat_rad) + height_m;
    let rn = prime_vertical_radius_m(lat_rad) + height_m;
    [
        vel_ned_m_s[1] / rn,
        -vel_ned_m_s[0] / rm,
        -vel_ned_m_s[1] * lat_rad.tan() / rn,
    ]
}

/// Geodetic (φ, λ, h) → ECEF, m.
pub fn llh_to_ecef(lat_rad: f64, lon_rad: f64, height_m: f64) -> Vec3 {
    let rn = prime_vertical_radius_m(lat_rad);
    let (sl, cl) = lat_rad.sin_cos();
    let (so, co) = lon_rad.sin_cos();
    [
        (rn + height_m) * cl * co,
        (rn + height_m) * cl * so,
        (rn * (1.0 - E2) + height_m) * sl,
    ]
}

/// ECEF → geodetic (φ, λ, h), by fixed-point iteration on φ (converges to < 1e-12 rad in
/// a few steps away from the Earth's centre). Height uses the form
/// h = p·cos φ + z·sin φ − a·√(1 − e² sin²φ), well conditioned at every latitude.
pub fn ecef_to_llh(r: Vec3) -> (f64, f64, f64) {
    let p = (r[0] * r[0] + r[1] * r[1]).sqrt();
    let lon = r[1].atan2(r[0]);
    let mut lat = r[2].atan2(p * (1.0 - E2));
    let height = |lat: f64| {
        let (s, c) = lat.sin_cos();
        p * c + r[2] * s - A_M * (1.0 - E2 * s * s).sqrt()
    };
    for _ in 0..10 {
        let rn = prime_vertical_radius_m(lat);
        let h = height(lat);
        let next = r[2].atan2(p * (1.0 - E2 * rn / (rn + h)));
        let done = (next - lat).abs() < 1e-15;
        lat = next;
        if done {
            break;
        }
    }
    (lat, lon, height(lat))
}

/// North/east/down offsets, m, of (φ₂, λ₂, h₂) from (φ₁, λ₁, h₁) for small separations,
/// using the radii at the first point: dN = Δφ(R_M + h), dE = Δλ(R_N + h)cos φ, dD = −Δh.
pub fn ned_offset_m(from: (f64, f64, f64), to: (f64, f64, f64)) -> Vec3 {
    let (lat, lon, h) = from;
    let rm = meridian_radius_m(lat) + h;
    let rn = prime_vertical_radius_m(lat) + h;
    let mut dlon = to.1 - lon;
    if dlon > std::f64::consts::PI {
        dlon -= 2.0 * std::f64::consts::PI;
    } else if dlon < -std::f64::consts::PI {
        dlon += 2.0 * std::f64::consts::PI;
    }
    [(to.0 - lat) * rm, dlon * rn * lat.cos(), -(to.2 - h)]
}

#[cfg(test)]
mod tests {
    use super::*;
    use driftless_model::units::DEG;

    #[test]
    fn normal_gravity_matches_published_values() {
        // WGS-84 normal gravity on the ellipsoid: equator 9.7803253359, pole 9.8321849378
        // (TR8350.2 Table 3.4).
        assert!((normal_gravity_m_s2(0.0, 0.0) - 9.780_325_335_9).abs() < 1e-9);
        assert!((normal_gravity_m_s2(90.0 * DEG, 0.0) - 9.832_184_937_8).abs() < 1e-8);
        // Free-air gradient ≈ −3.086e-6 s⁻² at mid latitude.
        let g0 = normal_gravity_m_s2(45.0 * DEG, 0.0);
        let g1 = normal_gravity_m_s2(45.0 * DEG, 1000.0);
        assert!(
            ((g1 - g0) / 1000.0 + 3.086e-6).abs() < 0.01e-6,
            "{}",
            (g1 - g0) / 1000.0
        );
    }

    #[test]
    fn radii_at_equator_and_pole() {
        assert!((prime_vertical_radius_m(0.0) - A_M).abs() < 1e-6);
        assert!((meridian_radius_m(0.0) - A_M * (1.0 - E2)).abs() < 1e-6);
        // At the pole both equal a²/b.
        let polar = A_M * A_M / B_M;
        assert!((meridian_radius_m(90.0 * DEG) - polar).abs() < 1e-6);
        assert!((prime_vertical_radius_m(90.0 * DEG) - polar).abs() < 1e-6);
    }

    #[test]
    fn ecef_round_trip() {
        for &(lat, lon, h) in &[
            (30.0, 114.0, 25.0),
            (-45.5, -70.25, 4200.0),
            (89.9, 10.0, -30.0),
            (0.0, 180.0, 0.0),
        ] {
            let r = llh_to_ecef(lat * DEG, lon * DEG, h);
            let (la, lo, hh) = ecef_to_llh(r);
            assert!((la - lat * DEG).abs() < 1e-12, "{lat}");
            assert!((lo - lon * DEG).abs() < 1e-12 || (lo.abs() - 180.0 * DEG).abs() < 1e-12);
            assert!((hh - h).abs() < 1e-6, "{hh} vs {h}");
        }
    }

    #[test]
    fn ned_offset_matches_ecef_distance_for_short_baselines() {
        let a = (30.5 * DEG, 114.3 * DEG, 20.0);
        let b = (a.0 + 1e-5, a.1 + 2e-5, 21.5);
        let d = ned_offset_m(a, b);
        let (ra, rb) = (llh_to_ecef(a.0, a.1, a.2), llh_to_ecef(b.0, b.1, b.2));
        let dist =
            ((ra[0] - rb[0]).powi(2) + (ra[1] - rb[1]).powi(2) + (ra[2] - rb[2]).powi(2)).sqrt();
        let dn = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        assert!((dist - dn).abs() < 1e-3, "{dist} {dn}");
    }

    #[test]
    fn earth_and_transport_rates() {
        let w = earth_rate_ned(30.0 * DEG);
        assert!((w[0] - OMEGA_IE * (3f64).sqrt() / 2.0).abs() < 1e-18);
        assert!((w[2] + OMEGA_IE / 2.0).abs() < 1e-18);
        // Driving east at the equator: ω_en = (v/R_N, 0, 0).
        let t = transport_rate_ned(0.0, 0.0, [0.0, 10.0, 0.0]);
        assert!((t[0] - 10.0 / A_M).abs() < 1e-18 && t[1] == 0.0 && t[2].abs() < 1e-20);
    }
}
