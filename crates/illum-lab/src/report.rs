//! Text outputs of the measuring tools: CSV (RFC 4180, by the csv crate), written atomically,
//! Markdown tables, and the host a table's times were measured on.

use std::io::Write as _;
use std::path::Path;

/// Writes `text` to `path` atomically (a reader never sees half a file).
pub fn write_text(path: &Path, text: &str) -> anyhow::Result<()> {
    illum_image::write_atomically(path, |file| {
        file.write_all(text.as_bytes()).map_err(|e| illum_image::ImageError::Io {
            path: path.to_path_buf(),
            action: "writing",
            source: e,
        })
    })?;
    Ok(())
}

/// A CSV file from a header and rows, quoted where a field needs it.
pub fn csv_text(header: &[&str], rows: &[Vec<String>]) -> anyhow::Result<String> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer.write_record(header)?;
    for row in rows {
        writer.write_record(row)?;
    }
    Ok(String::from_utf8(writer.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?)?)
}

/// A markdown table from a header and rows (a `|` inside a field is escaped).
pub fn markdown_table(header: &[&str], rows: &[Vec<String>]) -> String {
    let cell = |s: &str| s.replace('|', "\\|");
    let mut text = format!(
        "| {} |\n|{}\n",
        header.iter().map(|h| cell(h)).collect::<Vec<_>>().join(" | "),
        "---|".repeat(header.len())
    );
    for row in rows {
        text.push_str(&format!("| {} |\n", row.iter().map(|f| cell(f)).collect::<Vec<_>>().join(" | ")));
    }
    text
}

/// "Intel(R) Xeon(R) Processor, 2 vCPUs" from /proc/cpuinfo ("unknown CPU" elsewhere): the
/// host beside a table's absolute times.
pub fn host_cpu() -> String {
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    let model =
        info.lines().find_map(|l| Some(l.strip_prefix("model name")?.split_once(':')?.1.trim().to_owned()));
    let count = info.lines().filter(|l| l.starts_with("processor")).count();
    model.map_or("unknown CPU".to_owned(), |m| format!("{m}, {count} vCPUs"))
}

/// The host's one-minute load average, where the system tells it (Linux): other work on the host
/// slows every timed figure, and a table quoted without it cannot be judged.
pub fn load_average() -> Option<String> {
    let text = std::fs::read_to_string("/proc/loadavg").ok()?;
    text.split(' ').next().map(str::to_owned)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_rows_with_commas_in_a_field_keep_their_column_count() {
        let header = ["variant", "spp", "relmse"];
        let rows = vec![
            vec!["cosine, independent".to_owned(), "16".to_owned(), "0.01".to_owned()],
            vec!["say \"hi\", twice".to_owned(), "32".to_owned(), "0.005".to_owned()],
        ];
        let text = csv_text(&header, &rows).unwrap();
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        assert_eq!(reader.headers().unwrap().len(), 3);
        let read: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
        assert_eq!(read.len(), 2);
        for (record, row) in read.iter().zip(&rows) {
            assert_eq!(record.len(), 3, "{text}");
            assert_eq!(record.iter().collect::<Vec<_>>(), row.iter().map(String::as_str).collect::<Vec<_>>());
        }
    }

    #[test]
    fn a_markdown_table_has_one_separator_and_escapes_pipes() {
        let table = markdown_table(&["a", "b"], &[vec!["x|y".into(), "1".into()]]);
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(lines, ["| a | b |", "|---|---|", "| x\\|y | 1 |"]);
    }
}
