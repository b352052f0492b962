//! Deterministic IFC GlobalIds: 128 bits from a seeded hash of a stable key,
//! written in the 22-character IFC base64 alphabet.

const ALPHABET: &[u8; 64] = b"0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_$";

/// Finaliser of SplitMix64: spreads every input bit over the output.
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// Two independent FNV-1a lanes over the key, each mixed with the seed.
pub fn hash128(seed: u64, key: &str) -> u128 {
    let mut a: u64 = 0xcbf2_9ce4_8422_2325 ^ mix64(seed);
    let mut b: u64 = 0x6c62_272e_07bb_0142 ^ mix64(seed.rotate_left(32) ^ 0x9e37_79b9_7f4a_7c15);
    for &byte in key.as_bytes() {
        a = (a ^ byte as u64).wrapping_mul(0x0000_0100_0000_01b3);
        b = (b ^ byte as u64)
            .wrapping_mul(0x0000_0100_0000_01b3)
            .rotate_left(7);
    }
    let hi = mix64(a ^ key.len() as u64);
    let lo = mix64(b.wrapping_add(hi));
    ((hi as u128) << 64) | lo as u128
}

/// Encode 128 bits as an IFC GlobalId (first character carries the top 2 bits).
pub fn encode(bits: u128) -> String {
    let mut out = String::with_capacity(22);
    out.push(ALPHABET[(bits >> 126) as usize] as char);
    for k in (0..21).rev() {
        out.push(ALPHABET[((bits >> (6 * k)) & 63) as usize] as char);
    }
    out
}

/// GlobalId for `key` under `seed`.
pub fn global_id(seed: u64, key: &str) -> String {
    encode(hash128(seed, key))
}

/// Is `text` a well-formed GlobalId (22 characters of the alphabet, first one 0..3)?
pub fn is_valid(text: &str) -> bool {
    let b = text.as_bytes();
    b.len() == 22 && matches!(b[0], b'0'..=b'3') && b.iter().all(|c| ALPHABET.contains(c))
}
