//! CSV files of the tools: a header line, then one record per row, fields already formatted
//! by the caller (so each tool keeps its own number formats).

use std::path::Path;

/// Writes `header` and `records` to `path` (quoting fields only where needed).
pub fn write<I, R>(path: &Path, header: &[&str], records: I) -> csv::Result<()>
where
    I: IntoIterator<Item = R>,
    R: IntoIterator<Item = String>,
{
    let mut writer = csv::Writer::from_path(path)?;
    writer.write_record(header)?;
    for record in records {
        writer.write_record(record)?;
    }
    writer.flush()?;
    Ok(())
}

/// The records of the CSV file at `path`, checking that its header is `header`. Records may
/// have more fields than the header (files whose writer did not quote a field holding a
/// comma): the caller decides what to make of them.
pub fn read(path: &Path, header: &[&str]) -> Result<Vec<csv::StringRecord>, String> {
    let context = |e: csv::Error| format!("{}: {e}", path.display());
    let mut reader = csv::ReaderBuilder::new()
        .flexible(true)
        .from_path(path)
        .map_err(context)?;
    let found = reader.headers().map_err(context)?.clone();
    if found.iter().ne(header.iter().copied()) {
        return Err(format!(
            "{}: columns {:?}, expected {header:?}",
            path.display(),
            found.iter().collect::<Vec<_>>()
        ));
    }
    reader
        .records()
        .collect::<Result<Vec<_>, _>>()
        .map_err(context)
}

#[cfg(test)]
mod tests {
    use super::{read, write};

    /// Fields with commas, quotes and newlines come back as written; a wrong header is refused.
    #[test]
    fn fields_survive_a_round_trip() {
        let path = std::env::temp_dir().join(format!("so3fft-csv-out-{}.csv", std::process::id()));
        let rows = vec![
            vec!["a".to_string(), "x, y".to_string()],
            vec!["b \"quoted\"".to_string(), "two\nlines".to_string()],
        ];
        write(&path, &["name", "note"], rows.clone()).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("name,note\na,\"x, y\"\n"), "{text}");
        let back = read(&path, &["name", "note"]).unwrap();
        let back: Vec<Vec<String>> = back
            .iter()
            .map(|r| r.iter().map(str::to_string).collect())
            .collect();
        assert_eq!(back, rows);
        assert!(read(&path, &["name", "other"]).is_err());
        std::fs::remove_file(path).unwrap();
    }
}
