//! Decoding the JSON messages of `/gyro` and `/reference`: a fast path for the exact form
//! the writer produces (`{"rate_dps":1.5,"temperature_c":25.0,"status":null}`), and
//! serde_json for anything else, so both give the same values bit for bit (numbers are
//! parsed with correct rounding either way) and the same errors.

use serde::{Deserialize, Deserializer};

/// A decoded `/gyro` message: absent field → `None`, `null` → `Some(None)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct GyroFields {
    pub rate_dps: Option<Option<f64>>,
    pub temperature_c: Option<Option<f64>>,
}

/// Deserialize a field whose presence matters: absent → `None`, `null` → `Some(None)`.
fn present<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Option<f64>>, D::Error> {
    Option::<f64>::deserialize(d).map(Some)
}

#[derive(Deserialize)]
struct GyroIn {
    #[serde(default, deserialize_with = "present")]
    rate_dps: Option<Option<f64>>,
    #[serde(default, deserialize_with = "present")]
    temperature_c: Option<Option<f64>>,
    #[serde(default)]
    #[allow(dead_code)] // checked for type; `Row` has no status yet
    status: Option<u32>,
}

#[derive(Deserialize)]
struct ReferenceIn {
    #[serde(default, deserialize_with = "present")]
    angle_deg: Option<Option<f64>>,
}

/// Decode a `/gyro` message.
pub(super) fn gyro(data: &[u8]) -> Result<GyroFields, serde_json::Error> {
    if let Some(fields) = fast_gyro(data) {
        return Ok(fields);
    }
    let message: GyroIn = serde_json::from_slice(data)?;
    Ok(GyroFields {
        rate_dps: message.rate_dps,
        temperature_c: message.temperature_c,
    })
}

/// Decode a `/reference` message: its `angle_deg` field (absent → `None`).
pub(super) fn reference(data: &[u8]) -> Result<Option<Option<f64>>, serde_json::Error> {
    let mut cursor = Cursor(data);
    let fast = (|| {
        cursor.tag(br#"{"angle_deg":"#)?;
        let angle = cursor.number_or_null()?;
        cursor.tag(b"}")?;
        cursor.is_empty().then_some(Some(angle))
    })();
    match fast {
        Some(angle) => Ok(angle),
        None => serde_json::from_slice::<ReferenceIn>(data).map(|m| m.angle_deg),
    }
}

/// The writer's form: `{"rate_dps":N[,"temperature_c":N][,"status":null|U32]}` with no
/// white space; `None` for anything else.
fn fast_gyro(data: &[u8]) -> Option<GyroFields> {
    let mut cursor = Cursor(data);
    cursor.tag(br#"{"rate_dps":"#)?;
    let rate = cursor.number_or_null()?;
    let mut temperature = None;
    if cursor.tag(br#","temperature_c":"#).is_some() {
        temperature = Some(cursor.number_or_null()?);
    }
    if cursor.tag(br#","status":"#).is_some() && cursor.tag(b"null").is_none() {
        cursor.unsigned_u32()?;
    }
    cursor.tag(b"}")?;
    cursor.is_empty().then_some(GyroFields {
        rate_dps: Some(rate),
        temperature_c: temperature,
    })
}

/// The unread rest of a message.
struct Cursor<'a>(&'a [u8]);

impl Cursor<'_> {
    fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// Consume `tag` if the rest starts with it.
    fn tag(&mut self, tag: &[u8]) -> Option<()> {
        let rest = self.0.strip_prefix(tag)?;
        self.0 = rest;
        Some(())
    }

    /// Consume bytes while `pred` holds; how many.
    fn digits(&mut self) -> usize {
        let n = self.0.iter().take_while(|b| b.is_ascii_digit()).count();
        self.0 = &self.0[n..];
        n
    }

    /// `null` or a JSON number (strict grammar) that is finite as an `f64`.
    fn number_or_null(&mut self) -> Option<Option<f64>> {
        if self.tag(b"null").is_some() {
            return Some(None);
        }
        let start = self.0;
        let _ = self.tag(b"-");
        match self.0.first() {
            Some(b'0') => self.0 = &self.0[1..],
            Some(b'1'..=b'9') => {
                self.digits();
            }
            _ => return None,
        }
        if self.tag(b".").is_some() && self.digits() == 0 {
            return None;
        }
        if matches!(self.0.first(), Some(b'e' | b'E')) {
            self.0 = &self.0[1..];
            if matches!(self.0.first(), Some(b'+' | b'-')) {
                self.0 = &self.0[1..];
            }
            if self.digits() == 0 {
                return None;
            }
        }
        let number = &start[..start.len() - self.0.len()];
        let value = match crate::csv_log::parse_plain_decimal(number) {
            Some(value) => value,
            None => std::str::from_utf8(number).ok()?.parse().ok()?,
        };
        // Out of range: let serde_json decide (it refuses such numbers).
        value.is_finite().then_some(Some(value))
    }

    /// A JSON integer in `u32` range.
    fn unsigned_u32(&mut self) -> Option<u32> {
        let start = self.0;
        let n = self.digits();
        if n == 0 || (n > 1 && start[0] == b'0') {
            return None;
        }
        std::str::from_utf8(&start[..n]).ok()?.parse().ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast path and serde_json agree on every form, fast or not.
    #[test]
    fn fast_path_equals_serde() {
        let cases: &[&str] = &[
            r#"{"rate_dps":1.5,"temperature_c":25.0,"status":null}"#,
            r#"{"rate_dps":-0.000123456789012345,"status":null}"#,
            r#"{"rate_dps":null,"temperature_c":null,"status":7}"#,
            r#"{"rate_dps":1e-7,"temperature_c":-3E+2,"status":4294967295}"#,
            r#"{"rate_dps":0,"temperature_c":12.25}"#,
            r#"{"rate_dps":17}"#,
            r#"{"rate_dps":0.1000000000000000055511151231257827}"#,
            r#"{"rate_dps": 1.5}"#,
            r#"{"temperature_c":1,"rate_dps":2}"#,
            r#"{}"#,
        ];
        for text in cases {
            let serde: GyroIn = serde_json::from_str(text).unwrap();
            let got = gyro(text.as_bytes()).unwrap();
            assert_eq!(
                got.rate_dps.map(|r| r.map(f64::to_bits)),
                serde.rate_dps.map(|r| r.map(f64::to_bits)),
                "{text}"
            );
            assert_eq!(got.temperature_c, serde.temperature_c, "{text}");
        }
        for bad in [
            r#"{"rate_dps":01}"#,
            r#"{"rate_dps":1.}"#,
            r#"{"rate_dps":.5}"#,
            r#"{"rate_dps":1e400}"#,
            r#"{"rate_dps":"1"}"#,
            r#"{"rate_dps":1,"status":-1}"#,
            r#"{"rate_dps":1,"status":4294967296}"#,
            r#"{"rate_dps":inf}"#,
            r#"{"rate_dps":1"#,
        ] {
            assert!(serde_json::from_str::<GyroIn>(bad).is_err(), "{bad}");
            assert!(gyro(bad.as_bytes()).is_err(), "{bad}");
        }
        assert_eq!(
            reference(br#"{"angle_deg":-90.5}"#).unwrap(),
            Some(Some(-90.5))
        );
        assert_eq!(reference(br#"{"angle_deg":null}"#).unwrap(), Some(None));
        assert_eq!(reference(br#"{"other":1}"#).unwrap(), None);
        assert!(reference(br#"{"angle_deg":x}"#).is_err());
    }
}
