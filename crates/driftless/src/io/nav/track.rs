//! Navigation solution writers beyond KF-GINS's formats: a self-describing CSV and the
//! track as GeoJSON (RFC 7946: one `LineString` feature, WGS-84 longitude/latitude in
//! degrees, ellipsoidal height in metres as the third coordinate).

use super::types::NavSolution;
use crate::io::LogError;
use std::io::Write;
use std::path::Path;

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> LogError + '_ {
    move |error| LogError::Io {
        path: path.display().to_string(),
        error,
    }
}

/// Write the solution as CSV with a header naming each column and unit.
pub fn write_solution_csv(path: &Path, sol: &NavSolution) -> Result<(), LogError> {
    let (mut file, name) = crate::io::error::create_file(path)?;
    let mut w = std::io::BufWriter::with_capacity(1 << 20, &mut file);
    let e = io_err(path);
    writeln!(
        w,
        "time_s,lat_deg,lon_deg,height_m,vel_n_m_s,vel_e_m_s,vel_d_m_s,roll_deg,pitch_deg,yaw_deg"
    )
    .map_err(&e)?;
    for i in 0..sol.time_s.len() {
        let v = sol.vel_ned_m_s[i];
        let a = sol.roll_pitch_yaw_rad[i];
        writeln!(
            w,
            "{:.4},{:.9},{:.9},{:.4},{:.4},{:.4},{:.4},{:.5},{:.5},{:.5}",
            sol.time_s[i],
            sol.lat_rad[i].to_degrees(),
            sol.lon_rad[i].to_degrees(),
            sol.height_m[i],
            v[0],
            v[1],
            v[2],
            a[0].to_degrees(),
            a[1].to_degrees(),
            a[2].to_degrees()
        )
        .map_err(&e)?;
    }
    w.flush().map_err(&e)?;
    drop(w);
    crate::io::error::commit_file(file, &name)
}

/// Write the track as a GeoJSON `FeatureCollection` with one `LineString`, keeping every
/// `stride`-th epoch (and the last) so a 200 Hz solution stays light for map viewers.
pub fn write_track_geojson(path: &Path, sol: &NavSolution, stride: usize) -> Result<(), LogError> {
    let (mut file, name) = crate::io::error::create_file(path)?;
    let mut w = std::io::BufWriter::new(&mut file);
    let e = io_err(path);
    let n = sol.time_s.len();
    let stride = stride.max(1);
    write!(
        w,
        "{{\"type\":\"FeatureCollection\",\"features\":[{{\"type\":\"Feature\",\"properties\":{{\"name\":\"driftless track\",\"start_time_s\":{},\"end_time_s\":{}}},\"geometry\":{{\"type\":\"LineString\",\"coordinates\":[",
        sol.time_s.first().copied().unwrap_or(0.0),
        sol.time_s.last().copied().unwrap_or(0.0)
    )
    .map_err(&e)?;
    let mut first = true;
    for i in (0..n).filter(|i| i % stride == 0 || *i + 1 == n) {
        if !first {
            w.write_all(b",").map_err(&e)?;
        }
        first = false;
        write!(
            w,
            "[{:.8},{:.8},{:.3}]",
            sol.lon_rad[i].to_degrees(),
            sol.lat_rad[i].to_degrees(),
            sol.height_m[i]
        )
        .map_err(&e)?;
    }
    w.write_all(b"]}}]}\n").map_err(&e)?;
    w.flush().map_err(&e)?;
    drop(w);
    crate::io::error::commit_file(file, &name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geojson_is_lon_lat_height_and_csv_has_a_row_per_epoch() {
        let sol = NavSolution {
            time_s: vec![1.0, 2.0, 3.0],
            lat_rad: vec![0.5, 0.5001, 0.5002],
            lon_rad: vec![2.0, 2.0001, 2.0002],
            height_m: vec![10.0, 11.0, 12.0],
            vel_ned_m_s: vec![[1.0, 0.0, 0.0]; 3],
            roll_pitch_yaw_rad: vec![[0.0, 0.0, 0.1]; 3],
        };
        let dir = std::env::temp_dir().join(format!("driftless-track-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let g = dir.join("t.geojson");
        write_track_geojson(&g, &sol, 2).unwrap();
        let text = std::fs::read_to_string(&g).unwrap();
        // epochs 0 and 2 (stride 2, last kept), longitude first
        assert!(text.contains(&format!(
            "[{:.8},{:.8},10.000]",
            2f64.to_degrees(),
            0.5f64.to_degrees()
        )));
        assert_eq!(text.matches("],[").count(), 1);
        assert!(text.starts_with("{\"type\":\"FeatureCollection\""));
        let c = dir.join("t.csv");
        write_solution_csv(&c, &sol).unwrap();
        assert_eq!(std::fs::read_to_string(&c).unwrap().lines().count(), 4);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
