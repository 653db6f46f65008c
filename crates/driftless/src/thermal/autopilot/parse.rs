//! Reading PX4 and ArduPilot parameter files back into thermal-compensation coefficients
//! (syntax errors name file, line and column).

use super::*;

/// A parsed parameter: value text as written, its position, and the float32 it holds.
#[derive(Clone, Debug)]
pub(super) struct Entry {
    pub(super) value: f64,
    pub(super) line: usize,
    pub(super) column: usize,
    /// MAV_PARAM_TYPE (PX4 files only).
    pub(super) mav_type: Option<u8>,
}

/// Name → entry of a parameter file, duplicates refused.
pub(super) struct ParamFile {
    pub(super) file: String,
    pub(super) entries: BTreeMap<String, Entry>,
    pub(super) ignored: usize,
}

pub(super) fn syntax(file: &str, line: usize, column: usize, message: String) -> AutopilotError {
    AutopilotError::Syntax {
        file: file.to_owned(),
        line,
        column,
        message,
    }
}

/// Splits `line` into fields at `is_sep`, each with its 1-based character column.
pub(super) fn fields(line: &str, is_sep: impl Fn(char) -> bool) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut start: Option<(usize, usize)> = None; // (byte, column)
    for (col0, (bi, ch)) in line.char_indices().enumerate() {
        if is_sep(ch) {
            if let Some((s, c)) = start.take() {
                out.push((c, &line[s..bi]));
            }
        } else if start.is_none() {
            start = Some((bi, col0 + 1));
        }
    }
    if let Some((s, c)) = start {
        out.push((c, &line[s..]));
    }
    out
}

/// A parameter name field (column, text): letters, digits and `_` only.
pub(super) fn parameter_name<'a>(
    file: &str,
    line: usize,
    (col, name): (usize, &'a str),
) -> Result<&'a str, AutopilotError> {
    if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err(syntax(
            file,
            line,
            col,
            format!("{name:?} is not a parameter name"),
        ));
    }
    Ok(name)
}
/// Column to blame for a wrong field count: the first extra field, or just past the end.
pub(super) fn count_column(line: &str, f: &[(usize, &str)], want: usize) -> usize {
    f.get(want).map_or(line.chars().count() + 1, |x| x.0)
}

pub(super) fn parse_number(
    file: &str,
    line: usize,
    column: usize,
    text: &str,
) -> Result<f64, AutopilotError> {
    let v: f64 = text.parse().map_err(|_| {
        syntax(
            file,
            line,
            column,
            format!("value {text:?} is not a number"),
        )
    })?;
    if !v.is_finite() {
        return Err(syntax(
            file,
            line,
            column,
            format!("value {text:?} is not finite"),
        ));
    }
    Ok(v)
}

impl ParamFile {
    pub(super) fn insert(
        &mut self,
        name: &str,
        e: Entry,
        relevant: bool,
    ) -> Result<(), AutopilotError> {
        if !relevant {
            self.ignored += 1;
            return Ok(());
        }
        if let Some(prev) = self.entries.get(name) {
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("{name} given again (first on line {})", prev.line),
            ));
        }
        self.entries.insert(name.to_owned(), e);
        Ok(())
    }

    /// Takes a required float parameter as float32.
    pub(super) fn take_f32(&mut self, name: &str) -> Result<f32, AutopilotError> {
        self.take_opt_f32(name)?
            .ok_or_else(|| AutopilotError::Params {
                file: self.file.clone(),
                message: format!("missing required parameter {name}"),
            })
    }

    pub(super) fn take_opt_f32(&mut self, name: &str) -> Result<Option<f32>, AutopilotError> {
        let Some(e) = self.entries.remove(name) else {
            return Ok(None);
        };
        if let Some(t) = e.mav_type.filter(|t| *t != 9) {
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("{name} is a float parameter: type must be 9 (REAL32), not {t}"),
            ));
        }
        let f = e.value as f32;
        if !f.is_finite() {
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("{name} = {} overflows a float32", e.value),
            ));
        }
        Ok(Some(f))
    }

    pub(super) fn take_int(&mut self, name: &str) -> Result<i32, AutopilotError> {
        let Some(e) = self.entries.remove(name) else {
            return Err(AutopilotError::Params {
                file: self.file.clone(),
                message: format!("missing required parameter {name}"),
            });
        };
        if let Some(t) = e.mav_type.filter(|t| *t != 6) {
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("{name} is an integer parameter: type must be 6 (INT32), not {t}"),
            ));
        }
        if e.value.fract() != 0.0 || e.value < i32::MIN as f64 || e.value > i32::MAX as f64 {
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("{name} = {} is not a 32-bit integer", e.value),
            ));
        }
        Ok(e.value as i32)
    }

    /// Fails naming any parameter of the autopilot's namespace left unused.
    pub(super) fn finish(self) -> Result<usize, AutopilotError> {
        if let Some((name, e)) = self.entries.iter().next() {
            let hint = if name.contains("_SCL") {
                " (PX4 removed the thermal scale parameters; scale-factor terms have no place here)"
            } else {
                ""
            };
            return Err(syntax(
                &self.file,
                e.line,
                e.column,
                format!("unknown parameter {name}{hint}"),
            ));
        }
        Ok(self.ignored)
    }
}

/// PX4 thermal parameters of one triad of one instance.
#[derive(Clone, Debug, PartialEq)]
pub struct Px4Triad {
    /// `TC_A_ENABLE` / `TC_G_ENABLE` = 1.
    pub enabled: bool,
    /// `TC_*n_ID`.
    pub device_id: i32,
    /// `TREF`, `TMIN`, `TMAX`, °C.
    pub tref: f32,
    /// See `tref`.
    pub tmin: f32,
    /// See `tref`.
    pub tmax: f32,
    /// `X<k>_<axis>`: `x[k][axis]`.
    pub x: [[f32; 3]; 4],
    /// `CAL_ACCn_{X,Y,Z}OFF` / `CAL_GYROn_…` when the file has them (else PX4's 0 default
    /// is not assumed: the vehicle's own value applies).
    pub cal_offset: Option<[f32; 3]>,
}

impl Px4Triad {
    /// PX4's thermal offset at `t_c` (°C) in f64 arithmetic on the float32 parameters:
    /// X0 + X1·ΔT + X2·ΔT² + X3·ΔT³, ΔT = clamp(T, TMIN, TMAX) − TREF (upper bound tested
    /// first, as PX4 does); zero when disabled.
    pub fn offset(&self, t_c: f64) -> [f64; 3] {
        if !self.enabled {
            return [0.0; 3];
        }
        let dt = if t_c > self.tmax as f64 {
            self.tmax as f64 - self.tref as f64
        } else if t_c < self.tmin as f64 {
            self.tmin as f64 - self.tref as f64
        } else {
            t_c - self.tref as f64
        };
        std::array::from_fn(|i| {
            let x = |k: usize| self.x[k][i] as f64;
            x(0) + x(1) * dt + x(2) * dt * dt + x(3) * dt * dt * dt
        })
    }

    /// [`Self::offset`] in float32 arithmetic, in PX4's order of operations.
    pub fn offset_f32(&self, t_c: f32) -> [f32; 3] {
        if !self.enabled {
            return [0.0; 3];
        }
        let dt = if t_c > self.tmax {
            self.tmax - self.tref
        } else if t_c < self.tmin {
            self.tmin - self.tref
        } else {
            t_c - self.tref
        };
        let dt2 = dt * dt;
        let dt3 = dt2 * dt;
        std::array::from_fn(|i| {
            self.x[0][i] + self.x[1][i] * dt + self.x[2][i] * dt2 + self.x[3][i] * dt3
        })
    }

    /// Everything PX4 subtracts from the raw sample at `t_c`: thermal offset + CAL offset
    /// (0 when the file has none), f64 arithmetic.
    pub fn correction(&self, t_c: f64) -> [f64; 3] {
        let o = self.offset(t_c);
        let c = self.cal_offset.unwrap_or([0.0; 3]);
        std::array::from_fn(|i| o[i] + c[i] as f64)
    }

    /// [`Self::correction`] in float32 (PX4 subtracts the two in turn; summed here).
    pub fn correction_f32(&self, t_c: f32) -> [f32; 3] {
        let o = self.offset_f32(t_c);
        let c = self.cal_offset.unwrap_or([0.0; 3]);
        std::array::from_fn(|i| o[i] + c[i])
    }
}

/// The PX4 thermal parameters of one instance read from a `.params` file.
#[derive(Clone, Debug, PartialEq)]
pub struct Px4Thermal {
    /// Instance read.
    pub instance: usize,
    /// Accelerometer (None: no `TC_A*` parameters in the file).
    pub accel: Option<Px4Triad>,
    /// Gyro.
    pub gyro: Option<Px4Triad>,
    /// Parameters of other instances or subsystems, skipped.
    pub ignored: usize,
}

/// Reads the PX4 thermal parameters of `instance` from a QGroundControl `.params` text
/// (`file` names it in errors). Lines: `vehicle component NAME VALUE TYPE` separated by
/// tabs or spaces; `#` starts a comment line. Refused, naming line and column: a malformed
/// line, a non-numeric or non-finite value, a wrong type code, a duplicate, an unknown
/// `TC_A<n>_…`/`TC_G<n>_…` name (e.g. the removed `…_SCL_…`). Refused naming the file: a
/// triad with some but not all of its parameters, or a file without either triad.
pub fn parse_px4(text: &str, file: &str, instance: usize) -> Result<Px4Thermal, AutopilotError> {
    if instance >= PX4_INSTANCES {
        return Err(AutopilotError::Instance {
            instance,
            autopilot: "PX4",
            max: PX4_INSTANCES - 1,
        });
    }
    let mut pf = ParamFile {
        file: file.to_owned(),
        entries: BTreeMap::new(),
        ignored: 0,
    };
    let prefixes = [
        format!("TC_A{instance}_"),
        format!("TC_G{instance}_"),
        format!("CAL_ACC{instance}_"),
        format!("CAL_GYRO{instance}_"),
    ];
    for (li, raw) in text.lines().enumerate() {
        let line = li + 1;
        let body = raw.trim_end_matches('\r');
        if body.trim().is_empty() || body.trim_start().starts_with('#') {
            continue;
        }
        let f = fields(body, |c| c == '\t' || c == ' ');
        if f.len() != 5 {
            return Err(syntax(
                file,
                line,
                count_column(body, &f, 5),
                format!(
                    "expected 5 fields `vehicle-id component-id name value type`, found {}",
                    f.len()
                ),
            ));
        }
        for &(col, t) in &f[..2] {
            if t.parse::<u8>().is_err() {
                return Err(syntax(
                    file,
                    line,
                    col,
                    format!("{t:?} is not a vehicle/component id (0–255)"),
                ));
            }
        }
        let name = parameter_name(file, line, f[2])?;
        let (vcol, vtext) = f[3];
        let value = parse_number(file, line, vcol, vtext)?;
        let (tcol, ttext) = f[4];
        let mav_type: u8 = ttext.parse().map_err(|_| {
            syntax(
                file,
                line,
                tcol,
                format!("{ttext:?} is not a MAV_PARAM_TYPE code"),
            )
        })?;
        let cal_off = (name.starts_with(&prefixes[2]) || name.starts_with(&prefixes[3]))
            && name.ends_with("OFF");
        let relevant = name == "TC_A_ENABLE"
            || name == "TC_G_ENABLE"
            || name.starts_with(&prefixes[0])
            || name.starts_with(&prefixes[1])
            || cal_off;
        pf.insert(
            name,
            Entry {
                value,
                line,
                column: vcol,
                mav_type: Some(mav_type),
            },
            relevant,
        )?;
    }
    let mut triad = |letter: char, cal: &str| -> Result<Option<Px4Triad>, AutopilotError> {
        let g = format!("TC_{letter}{instance}_");
        let present = pf.entries.keys().any(|k| k.starts_with(&g));
        if !present {
            return Ok(None);
        }
        let enabled = pf.take_int(&format!("TC_{letter}_ENABLE"))? == 1;
        let device_id = pf.take_int(&format!("{g}ID"))?;
        let tref = pf.take_f32(&format!("{g}TREF"))?;
        let tmin = pf.take_f32(&format!("{g}TMIN"))?;
        let tmax = pf.take_f32(&format!("{g}TMAX"))?;
        if tmin > tmax {
            return Err(AutopilotError::Params {
                file: pf.file.clone(),
                message: format!("{g}TMIN {tmin} > {g}TMAX {tmax}"),
            });
        }
        let mut x = [[0.0f32; 3]; 4];
        for (k, row) in x.iter_mut().enumerate() {
            for (axis, v) in row.iter_mut().enumerate() {
                *v = pf.take_f32(&format!("{g}X{k}_{axis}"))?;
            }
        }
        let offs: Vec<Option<f32>> = AXES
            .iter()
            .map(|a| pf.take_opt_f32(&format!("CAL_{cal}{instance}_{a}OFF")))
            .collect::<Result<_, _>>()?;
        let cal_offset = match offs.as_slice() {
            [Some(a), Some(b), Some(c)] => Some([*a, *b, *c]),
            [None, None, None] => None,
            _ => {
                return Err(AutopilotError::Params {
                    file: pf.file.clone(),
                    message: format!("CAL_{cal}{instance}_XOFF/YOFF/ZOFF: give all three or none"),
                });
            }
        };
        Ok(Some(Px4Triad {
            enabled,
            device_id,
            tref,
            tmin,
            tmax,
            x,
            cal_offset,
        }))
    };
    let accel = triad('A', "ACC")?;
    let gyro = triad('G', "GYRO")?;
    if accel.is_none() && gyro.is_none() {
        return Err(AutopilotError::Params {
            file: file.to_owned(),
            message: format!("no TC_A{instance}_* or TC_G{instance}_* parameters"),
        });
    }
    let ignored = pf.finish()?;
    Ok(Px4Thermal {
        instance,
        accel,
        gyro,
        ignored,
    })
}

/// ArduPilot `INS_TCAL<n+1>_*` parameters and the calibration temperature/offsets read.
#[derive(Clone, Debug, PartialEq)]
pub struct ArduPilotTcal {
    /// Instance read (0 → `INS_TCAL1_`).
    pub instance: usize,
    /// `ENABLE` (0 disabled, 1 enabled, 2 learning; only 1 applies the correction).
    pub enable: i32,
    /// `TMIN`, °C.
    pub tmin: f32,
    /// `TMAX`, °C.
    pub tmax: f32,
    /// `ACC<k>_<axis>`: `acc[k − 1][axis]` (scaled by 1e6).
    pub acc: [[f32; 3]; 3],
    /// `GYR<k>_<axis>`.
    pub gyr: [[f32; 3]; 3],
    /// `INS_ACC<n+1>_CALTEMP` (ArduPilot's default −300 when absent).
    pub acc_caltemp: f32,
    /// `INS_GYR<n+1>_CALTEMP`.
    pub gyr_caltemp: f32,
    /// `INS_ACC[n+1]OFFS_*` when present.
    pub acc_offs: Option<[f32; 3]>,
    /// `INS_GYR[n+1]OFFS_*` when present.
    pub gyr_offs: Option<[f32; 3]>,
    /// Other parameters, skipped.
    pub ignored: usize,
}

impl ArduPilotTcal {
    pub(super) fn poly(c: &[[f32; 3]; 3], axis: usize, d: f64) -> f64 {
        let a = |k: usize| c[k][axis] as f64;
        (a(0) + (a(1) + a(2) * d) * d) * d / ARDUPILOT_COEFF_SCALE
    }

    /// What ArduPilot subtracts from the raw sample at `t_c`, f64 arithmetic on the float32
    /// parameters: P(Tc − 35) − P(Tcal − 35) (when ENABLE = 1) + OFFS (when given).
    pub fn correction(&self, accel: bool, t_c: f64) -> [f64; 3] {
        let (c, cal, offs) = if accel {
            (&self.acc, self.acc_caltemp, self.acc_offs)
        } else {
            (&self.gyr, self.gyr_caltemp, self.gyr_offs)
        };
        let (lo, hi) = (self.tmin as f64, self.tmax as f64);
        // constrain_float: lower bound first, then upper.
        let clamp = |t: f64| {
            if t < lo {
                lo
            } else if t > hi {
                hi
            } else {
                t
            }
        };
        let tc = clamp(t_c);
        let tcal = clamp(cal as f64);
        let o = offs.unwrap_or([0.0; 3]);
        std::array::from_fn(|i| {
            let th = if self.enable == 1 {
                Self::poly(c, i, tc - ARDUPILOT_TEMP_REFERENCE_C)
                    - Self::poly(c, i, tcal - ARDUPILOT_TEMP_REFERENCE_C)
            } else {
                0.0
            };
            th + o[i] as f64
        })
    }

    /// [`Self::correction`] in float32 arithmetic, in ArduPilot's order of operations
    /// (the sample is corrected in two steps; the net subtracted amount is returned).
    pub fn correction_f32(&self, accel: bool, t_c: f32) -> [f32; 3] {
        let (c, cal, offs) = if accel {
            (&self.acc, self.acc_caltemp, self.acc_offs)
        } else {
            (&self.gyr, self.gyr_caltemp, self.gyr_offs)
        };
        let clamp = |t: f32| {
            if t < self.tmin {
                self.tmin
            } else if t > self.tmax {
                self.tmax
            } else {
                t
            }
        };
        let p = |axis: usize, d: f32| {
            (c[0][axis] + (c[1][axis] + c[2][axis] * d) * d) * d * (1.0e-6f64 as f32)
        };
        let (tc, tcal) = (clamp(t_c), clamp(cal));
        let refc = ARDUPILOT_TEMP_REFERENCE_C as f32;
        let o = offs.unwrap_or([0.0; 3]);
        std::array::from_fn(|i| {
            let th = if self.enable == 1 {
                p(i, tc - refc) - p(i, tcal - refc)
            } else {
                0.0
            };
            th + o[i]
        })
    }
}

/// Reads `INS_TCAL<instance+1>_*` (all 21 required), `INS_ACC<n>_CALTEMP`,
/// `INS_GYR<n>_CALTEMP` and the instance's `INS_ACC…OFFS_*`/`INS_GYR…OFFS_*` (optional)
/// from a Mission Planner `.param` text: `NAME,VALUE` (or `NAME VALUE`, `NAME\tVALUE`) per
/// line, `#` starts a comment (also after the value). Errors as [`parse_px4`].
pub fn parse_ardupilot(
    text: &str,
    file: &str,
    instance: usize,
) -> Result<ArduPilotTcal, AutopilotError> {
    if instance >= ARDUPILOT_INSTANCES {
        return Err(AutopilotError::Instance {
            instance,
            autopilot: "ArduPilot",
            max: ARDUPILOT_INSTANCES - 1,
        });
    }
    let n1 = instance + 1;
    let g = format!("INS_TCAL{n1}_");
    let acc_cal = format!("INS_ACC{n1}_CALTEMP");
    let gyr_cal = format!("INS_GYR{n1}_CALTEMP");
    let offs: Vec<String> = [true, false]
        .iter()
        .flat_map(|&a| {
            AXES.iter()
                .map(move |&x| ardupilot_offs_name(a, instance, x))
        })
        .collect();
    let mut pf = ParamFile {
        file: file.to_owned(),
        entries: BTreeMap::new(),
        ignored: 0,
    };
    for (li, raw) in text.lines().enumerate() {
        let line = li + 1;
        let body = raw.trim_end_matches('\r');
        let body = body.split('#').next().unwrap_or("");
        if body.trim().is_empty() {
            continue;
        }
        let f = fields(body, |c| c == ',' || c == ' ' || c == '\t');
        if f.len() != 2 {
            return Err(syntax(
                file,
                line,
                count_column(body, &f, 2),
                format!("expected `NAME,VALUE`, found {} fields", f.len()),
            ));
        }
        let name = parameter_name(file, line, f[0])?;
        let (vcol, vtext) = f[1];
        let value = parse_number(file, line, vcol, vtext)?;
        let relevant = name.starts_with(&g)
            || name == acc_cal
            || name == gyr_cal
            || offs.iter().any(|o| o == name);
        pf.insert(
            name,
            Entry {
                value,
                line,
                column: vcol,
                mav_type: None,
            },
            relevant,
        )?;
    }
    if !pf.entries.keys().any(|k| k.starts_with(&g)) {
        return Err(AutopilotError::Params {
            file: file.to_owned(),
            message: format!("no {g}* parameters"),
        });
    }
    let enable = pf.take_int(&format!("{g}ENABLE"))?;
    let tmin = pf.take_f32(&format!("{g}TMIN"))?;
    let tmax = pf.take_f32(&format!("{g}TMAX"))?;
    if tmin > tmax {
        return Err(AutopilotError::Params {
            file: file.to_owned(),
            message: format!("{g}TMIN {tmin} > {g}TMAX {tmax}"),
        });
    }
    let mut acc = [[0.0f32; 3]; 3];
    let mut gyr = [[0.0f32; 3]; 3];
    for k in 0..3 {
        for (axis, a) in AXES.iter().enumerate() {
            acc[k][axis] = pf.take_f32(&format!("{g}ACC{}_{a}", k + 1))?;
            gyr[k][axis] = pf.take_f32(&format!("{g}GYR{}_{a}", k + 1))?;
        }
    }
    let acc_caltemp = pf
        .take_opt_f32(&acc_cal)?
        .unwrap_or(ARDUPILOT_CALTEMP_DEFAULT_C);
    let gyr_caltemp = pf
        .take_opt_f32(&gyr_cal)?
        .unwrap_or(ARDUPILOT_CALTEMP_DEFAULT_C);
    let mut triple = |names: &[String]| -> Result<Option<[f32; 3]>, AutopilotError> {
        let v: Vec<Option<f32>> = names
            .iter()
            .map(|n| pf.take_opt_f32(n))
            .collect::<Result<_, _>>()?;
        match v.as_slice() {
            [Some(a), Some(b), Some(c)] => Ok(Some([*a, *b, *c])),
            [None, None, None] => Ok(None),
            _ => Err(AutopilotError::Params {
                file: file.to_owned(),
                message: format!("{}: give all three axes or none", names.join("/")),
            }),
        }
    };
    let acc_offs = triple(&offs[..3])?;
    let gyr_offs = triple(&offs[3..])?;
    let ignored = pf.finish()?;
    Ok(ArduPilotTcal {
        instance,
        enable,
        tmin,
        tmax,
        acc,
        gyr,
        acc_caltemp,
        gyr_caltemp,
        acc_offs,
        gyr_offs,
        ignored,
    })
}
