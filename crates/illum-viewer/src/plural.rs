//! Counts in words, as the viewer's lines print them.

/// `n` and the noun in the number it takes ("1 frame", "2 frames").
pub fn count(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

#[cfg(test)]
mod tests {
    #[test]
    fn counts_take_the_nouns_number() {
        assert_eq!(super::count(1, "frame", "frames"), "1 frame");
        assert_eq!(super::count(0, "frame", "frames"), "0 frames");
        assert_eq!(super::count(30, "refresh", "refreshes"), "30 refreshes");
    }
}
