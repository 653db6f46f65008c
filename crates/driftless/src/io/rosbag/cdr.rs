//! Decoding of `sensor_msgs/Imu` and `sensor_msgs/Temperature` in the two ROS
//! serializations:
//!
//! * ROS 1: little-endian, no padding; `std_msgs/Header` = `u32 seq, u32 sec, u32 nsec,
//!   string frame_id` (`u32` length, bytes).
//! * ROS 2 CDR (OMG XCDR1 as used by ROS 2): a 4-byte encapsulation header (`00 01` little-,
//!   `00 00` big-endian), then primitives aligned to their size counted from the end of that
//!   header; `Header` = `i32 sec, u32 nanosec, string frame_id` (`u32` length counting the
//!   terminating NUL, bytes).
//!
//! After the header, `Imu` is 37 `float64`: orientation (4), its covariance (9),
//! angular_velocity (3, rad/s), its covariance (9), linear_acceleration (3, m/s²), its
//! covariance (9); `Temperature` is `float64 temperature` (°C) and `float64 variance`.

use super::{Encoding, ImuSample};

/// A cursor over one message's bytes.
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
    /// Where alignment counts from (after the CDR encapsulation header).
    origin: usize,
    big_endian: bool,
    aligned: bool,
}

impl<'a> Reader<'a> {
    fn new(b: &'a [u8], encoding: Encoding) -> Result<Self, String> {
        match encoding {
            Encoding::Ros1 => Ok(Reader {
                b,
                at: 0,
                origin: 0,
                big_endian: false,
                aligned: false,
            }),
            Encoding::Cdr => {
                let big_endian = match b.get(..2) {
                    Some([0, 1]) => false,
                    Some([0, 0]) => true,
                    Some(h) => {
                        return Err(format!(
                            "CDR encapsulation {:02x} {:02x}: only plain CDR (00 00 / 00 01) is \
                             read",
                            h[0], h[1]
                        ));
                    }
                    None => return Err("shorter than the CDR encapsulation header".into()),
                };
                Ok(Reader {
                    b,
                    at: 4,
                    origin: 4,
                    big_endian,
                    aligned: true,
                })
            }
        }
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N], String> {
        if self.aligned {
            let rel = self.at.saturating_sub(self.origin);
            self.at += (N - rel % N) % N;
        }
        let bytes: [u8; N] = self
            .b
            .get(self.at..self.at.saturating_add(N))
            .and_then(|s| s.try_into().ok())
            .ok_or_else(|| {
                format!(
                    "message of {} bytes ends before its field at byte {}",
                    self.b.len(),
                    self.at
                )
            })?;
        self.at += N;
        Ok(bytes)
    }

    fn u32(&mut self) -> Result<u32, String> {
        let b = self.take::<4>()?;
        Ok(if self.big_endian {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        })
    }

    fn f64(&mut self) -> Result<f64, String> {
        let b = self.take::<8>()?;
        Ok(if self.big_endian {
            f64::from_be_bytes(b)
        } else {
            f64::from_le_bytes(b)
        })
    }

    fn skip_string(&mut self) -> Result<(), String> {
        let len = self.u32()? as usize;
        if len > self.b.len().saturating_sub(self.at) {
            return Err(format!(
                "frame_id of {len} bytes runs past the message's {} bytes",
                self.b.len()
            ));
        }
        self.at += len;
        Ok(())
    }

    /// `std_msgs/Header`: the stamp in ns since the epoch (`sec · 1e9 + nanosec`).
    fn header_stamp_ns(&mut self, encoding: Encoding) -> Result<i64, String> {
        if encoding == Encoding::Ros1 {
            self.u32()?; // seq
        }
        let sec_bits = self.u32()?;
        let sec = match encoding {
            Encoding::Ros1 => i64::from(sec_bits),
            Encoding::Cdr => i64::from(sec_bits as i32),
        };
        let nsec = self.u32()?;
        if nsec >= 1_000_000_000 {
            return Err(format!(
                "header stamp nanoseconds {nsec} out of range (0 to 999999999)"
            ));
        }
        self.skip_string()?;
        Ok(sec * 1_000_000_000 + i64::from(nsec))
    }
}

/// Decodes one `sensor_msgs/Imu` message.
pub(crate) fn decode_imu(b: &[u8], encoding: Encoding) -> Result<ImuSample, String> {
    let mut r = Reader::new(b, encoding)?;
    let stamp_ns = r.header_stamp_ns(encoding)?;
    let mut v = [0.0; 37];
    for x in &mut v {
        *x = r.f64()?;
    }
    Ok(ImuSample {
        stamp_ns,
        gyro_rad_s: [v[13], v[14], v[15]],
        acc_m_s2: [v[25], v[26], v[27]],
    })
}

/// Decodes one `sensor_msgs/Temperature` message: (stamp, s; temperature, °C).
pub(crate) fn decode_temperature(b: &[u8], encoding: Encoding) -> Result<(f64, f64), String> {
    let mut r = Reader::new(b, encoding)?;
    let stamp_s = super::seconds_of_ns(r.header_stamp_ns(encoding)?);
    let celsius = r.f64()?;
    r.f64()?; // variance
    Ok((stamp_s, celsius))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cdr_imu(frame: &str) -> Vec<u8> {
        let mut b = vec![0, 1, 0, 0];
        b.extend(7i32.to_le_bytes());
        b.extend(500_000_000u32.to_le_bytes());
        b.extend((frame.len() as u32 + 1).to_le_bytes());
        b.extend(frame.as_bytes());
        b.push(0);
        while (b.len() - 4) % 8 != 0 {
            b.push(0);
        }
        for i in 0..37 {
            b.extend((i as f64).to_le_bytes());
        }
        b
    }

    #[test]
    fn cdr_imu_aligns_after_the_frame_id() {
        for frame in ["", "imu", "imu_link"] {
            let s = decode_imu(&cdr_imu(frame), Encoding::Cdr).unwrap();
            assert_eq!(s.stamp_ns, 7_500_000_000);
            assert_eq!(s.gyro_rad_s, [13.0, 14.0, 15.0]);
            assert_eq!(s.acc_m_s2, [25.0, 26.0, 27.0]);
        }
    }

    #[test]
    fn cut_messages_are_errors() {
        let b = cdr_imu("imu");
        for n in 0..b.len() {
            assert!(decode_imu(&b[..n], Encoding::Cdr).is_err());
            let _ = decode_imu(&b[..n], Encoding::Ros1);
        }
    }
}
