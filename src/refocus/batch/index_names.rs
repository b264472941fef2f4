//! The names the dataset index takes at a batch's out-dir root: `index.jsonl` and its parts
//! `index.part-K-of-N.jsonl`. A name is one of them only if it is exactly what the writer
//! makes (`index.part-00-of-01.jsonl` and `index.part-+0-of-+1.jsonl` are a user's files), with
//! 0 <= K < N: only these names are ever removed or joined, and no frame may take one.

/// The joined index's file name, at the out-dir's root.
pub const INDEX_NAME: &str = "index.jsonl";

/// Part `index` of `count`'s file name.
pub(super) fn part_name(index: usize, count: usize) -> String {
    format!("index.part-{index}-of-{count}.jsonl")
}

/// (K, N) of a part's file name: only the name [`part_name`] writes, with K < N.
pub(super) fn parse_part_name(name: &str) -> Option<(usize, usize)> {
    let rest = name.strip_prefix("index.part-")?.strip_suffix(".jsonl")?;
    let (k, n) = rest.split_once("-of-")?;
    let (k, n) = (k.parse().ok()?, n.parse().ok()?);
    (k < n && part_name(k, n) == name).then_some((k, n))
}

/// Whether `name` is the index's or one of its parts'.
pub fn is_index_name(name: &str) -> bool {
    name == INDEX_NAME || parse_part_name(name).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_writers_own_names_are_parts() {
        assert_eq!(parse_part_name(&part_name(3, 8)), Some((3, 8)));
        assert_eq!(parse_part_name(&part_name(0, 1)), Some((0, 1)));
        for name in [
            "index.jsonl",
            "index.part-x-of-2.jsonl",
            "index.part-00-of-01.jsonl",
            "index.part-+0-of-+1.jsonl",
            "index.part-0-of-0.jsonl",
            "index.part-2-of-2.jsonl",
            "index.part- 0-of-1.jsonl",
        ] {
            assert_eq!(parse_part_name(name), None, "{name}");
        }
        assert!(is_index_name("index.jsonl") && is_index_name("index.part-1-of-2.jsonl"));
        assert!(!is_index_name("index.part-01-of-2.jsonl") && !is_index_name("index.json"));
    }
}
