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

/// The decimal digits of `text` from `i` on, appended to `mantissa` (wrapping: it is only
/// used for at most 19 digits); `i` moves past them. How many.
fn take_digits(text: &[u8], i: &mut usize, mantissa: &mut u64) -> usize {
    let from = *i;
    while let Some(d) = text
        .get(*i)
        .map(|b| b.wrapping_sub(b'0'))
        .filter(|d| *d < 10)
    {
        *mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
        *i += 1;
    }
    *i - from
}

/// `mantissa / 10^decimals` correctly rounded, for a mantissa above 2^53 (not exact as an
/// `f64`), when it can be decided in 128-bit integers; `None` otherwise (a tie, or numbers
/// too large for the check). The `f64` quotient of the rounded mantissa is within an ulp
/// or so of the true value; the candidate (or its neighbour) is the answer if the true
/// value lies strictly between its two half-ulp midpoints, which is checked exactly:
/// `m · 2^(1-e)` against `(2M ± 1) · 10^decimals`, for the candidate `M · 2^e`.
fn checked_quotient(mantissa: u64, decimals: usize) -> Option<f64> {
    let pow10 = 10_u128.checked_pow(u32::try_from(decimals).ok()?)?;
    let mut candidate = mantissa as f64 / pow10 as f64;
    if !candidate.is_normal() {
        return None;
    }
    // The true value scaled by 2^(1-e): numerator `scaled`, denominator `pow10`; the
    // candidate's neighbours share its exponent (checked below), so `e` is fixed.
    let bits = candidate.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i32 - 1075;
    let shift = u32::try_from(1 - e).ok()?;
    if 64 - mantissa.leading_zeros() + shift > 127 {
        return None;
    }
    let scaled = u128::from(mantissa) << shift;
    for _ in 0..2 {
        let bits = candidate.to_bits();
        if ((bits >> 52) & 0x7ff) as i32 - 1075 != e {
            return None; // crossed a power of two
        }
        let m = u128::from((bits & ((1 << 52) - 1)) | (1 << 52));
        let below = (2 * m - 1).checked_mul(pow10)?;
        let above = (2 * m + 1).checked_mul(pow10)?;
        if below < scaled && scaled < above {
            return Some(candidate);
        }
        if scaled == below || scaled == above {
            return None; // a tie: left to the standard parser
        }
        candidate = f64::from_bits(if scaled > above { bits + 1 } else { bits - 1 });
    }
    None
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

    /// `null` or a JSON number (strict grammar) that is finite as an `f64`. The digits
    /// are gathered while the grammar is checked: up to 19 of them with no exponent, an
    /// exact mantissa (at most 2^53) and at most 22 decimals give the value by one
    /// correctly rounded division, as [`crate::csv_log::parse_plain_decimal`] does;
    /// anything else goes to the standard library's parser.
    fn number_or_null(&mut self) -> Option<Option<f64>> {
        const POW10: [f64; 23] = [
            1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
            1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
        ];
        if self.tag(b"null").is_some() {
            return Some(None);
        }
        let text = self.0;
        let negative = text.first() == Some(&b'-');
        let mut i = usize::from(negative);
        let mut mantissa = 0_u64;
        let mut digits = 0_usize;
        match text.get(i) {
            Some(b'0') => {
                i += 1;
                digits += 1;
            }
            Some(b'1'..=b'9') => digits += take_digits(text, &mut i, &mut mantissa),
            _ => return None,
        }
        let mut decimals = 0;
        if text.get(i) == Some(&b'.') {
            i += 1;
            decimals = take_digits(text, &mut i, &mut mantissa);
            if decimals == 0 {
                return None;
            }
            digits += decimals;
        }
        let mut plain = true;
        if matches!(text.get(i), Some(b'e' | b'E')) {
            plain = false;
            i += 1;
            if matches!(text.get(i), Some(b'+' | b'-')) {
                i += 1;
            }
            let from = i;
            while text.get(i).is_some_and(u8::is_ascii_digit) {
                i += 1;
            }
            if i == from {
                return None;
            }
        }
        let number = text.get(..i)?;
        self.0 = text.get(i..)?;
        let exact = match POW10.get(decimals) {
            Some(scale) if plain && digits <= 19 && mantissa <= 1 << 53 => {
                Some(mantissa as f64 / scale)
            }
            Some(_) if plain && digits <= 19 => checked_quotient(mantissa, decimals),
            _ => None,
        };
        let value = match exact {
            Some(value) if negative => -value,
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

    /// The fast number path gives serde_json's value, bit for bit, on numbers written
    /// every way: shortest round trip (up to 17 significant digits), fixed decimals, long
    /// mantissas, exponents, zeros.
    #[test]
    fn numbers_equal_serde_bit_for_bit() {
        let mut state = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut texts = vec![
            "0".to_string(),
            "-0".into(),
            "-0.0".into(),
            "9007199254740992".into(),
            "9007199254740993".into(),
            "0.9007199254740993".into(),
            "1234567890123456789".into(),
            "12345678901234567890".into(),
            "0.0000000000000000000001".into(),
            "0.00000000000000000000001".into(),
        ];
        for _ in 0..20_000 {
            let bits = next();
            let x = f64::from_bits(bits);
            if !x.is_finite() {
                continue;
            }
            let scaled = (bits >> 11) as f64 / (1_u64 << 53) as f64 * 1e3 - 500.0;
            texts.push(format!("{x}"));
            texts.push(format!("{x:e}"));
            texts.push(format!("{scaled}"));
            texts.push(format!("{scaled:.3}"));
            texts.push(format!("{scaled:.12}"));
            texts.push(format!("{scaled:.20}"));
        }
        for text in &texts {
            let json = format!(r#"{{"rate_dps":{text}}}"#);
            let serde = serde_json::from_str::<GyroIn>(&json).map(|m| m.rate_dps);
            let fast = gyro(json.as_bytes()).map(|m| m.rate_dps);
            match (serde, fast) {
                (Ok(a), Ok(b)) => assert_eq!(
                    a.map(|v| v.map(f64::to_bits)),
                    b.map(|v| v.map(f64::to_bits)),
                    "{text}"
                ),
                (a, b) => assert_eq!(a.is_err(), b.is_err(), "{text}"),
            }
        }
    }

    /// Mantissas above 2^53 (up to 19 digits) with 0 to 22 decimals, and the tie-prone
    /// ones near half-ulp boundaries: [`checked_quotient`] gives the standard parser's value
    /// or none.
    #[test]
    fn checked_quotient_equals_the_standard_parser() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let mut decided = 0;
        for i in 0..400_000 {
            let mantissa = match i % 4 {
                0 => (1 << 53) + next() % (1 << 60),
                1 => next() % 10_000_000_000_000_000_000,
                // Shortest forms of doubles near 1 and 25 (17 digits).
                2 => 10_000_000_000_000_000 + next() % 90_000_000_000_000_000,
                _ => (next() % (1 << 11)) << 53 | 1 << 52, // multiples of large powers of two
            };
            if mantissa <= 1 << 53 {
                continue;
            }
            let decimals = (next() % 23) as usize;
            let digits = mantissa.to_string();
            let text = if decimals == 0 {
                digits
            } else if digits.len() > decimals {
                let (a, b) = digits.split_at(digits.len() - decimals);
                format!("{a}.{b}")
            } else {
                format!("0.{}{digits}", "0".repeat(decimals - digits.len()))
            };
            let want: f64 = text.parse().unwrap();
            if let Some(got) = checked_quotient(mantissa, decimals) {
                decided += 1;
                assert_eq!(got.to_bits(), want.to_bits(), "{text}");
            }
            let json = format!(r#"{{"rate_dps":{text}}}"#);
            let fast = gyro(json.as_bytes()).unwrap().rate_dps;
            assert_eq!(fast, Some(Some(want)), "{text}");
        }
        assert!(decided > 200_000, "{decided}");
    }
}
