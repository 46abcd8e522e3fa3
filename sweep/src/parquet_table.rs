//! `results.parquet`: the finished table in Parquet, written beside `results.csv` once every run is in
//! (to a temporary file renamed over it, so a killed sweep never leaves a torn one). The CSV stays the
//! resumable record; this is its typed copy for pandas, polars, Arrow and Spark. A column whose cells
//! are all integers is INT64, all numbers DOUBLE, otherwise a UTF-8 string; an empty cell is a null.
use crate::error::{Result, SweepError};
use parquet::basic::{ConvertedType, Repetition, Type as PhysicalType};
use parquet::column::writer::ColumnWriter;
use parquet::data_type::ByteArray;
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use std::path::Path;
use std::sync::Arc;

pub const PARQUET_FILE: &str = "results.parquet";

/// How a column's cells are stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Int,
    Double,
    Text,
}

fn kind_of<'a>(cells: impl Iterator<Item = &'a str>) -> Kind {
    let mut kind = Kind::Int;
    for cell in cells.filter(|c| !c.is_empty()) {
        if kind == Kind::Int && cell.parse::<i64>().is_err() {
            kind = Kind::Double;
        }
        if kind == Kind::Double && cell.parse::<f64>().is_err() {
            return Kind::Text;
        }
    }
    kind
}

fn err(path: &Path, e: impl std::fmt::Display) -> SweepError {
    SweepError::io(
        format!("writing {}", path.display()),
        std::io::Error::other(e.to_string()),
    )
}

fn cell(row: &[String], c: usize) -> &str {
    row.get(c).map(String::as_str).unwrap_or("")
}

/// Writes `rows` (cells in `columns` order) as a Parquet file at `path`.
pub fn write_parquet(path: &Path, columns: &[String], rows: &[&[String]]) -> Result<()> {
    let kinds: Vec<Kind> = (0..columns.len())
        .map(|c| kind_of(rows.iter().map(|r| cell(r, c))))
        .collect();
    let fields = columns
        .iter()
        .zip(&kinds)
        .map(|(name, kind)| {
            let builder = match kind {
                Kind::Int => Type::primitive_type_builder(name, PhysicalType::INT64),
                Kind::Double => Type::primitive_type_builder(name, PhysicalType::DOUBLE),
                Kind::Text => Type::primitive_type_builder(name, PhysicalType::BYTE_ARRAY)
                    .with_converted_type(ConvertedType::UTF8),
            };
            builder
                .with_repetition(Repetition::OPTIONAL)
                .build()
                .map(Arc::new)
        })
        .collect::<std::result::Result<Vec<_>, _>>()
        .map_err(|e| err(path, e))?;
    let schema = Type::group_type_builder("results")
        .with_fields(fields)
        .build()
        .map_err(|e| err(path, e))?;
    let tmp = path.with_extension("parquet.tmp");
    let file = std::fs::File::create(&tmp)
        .map_err(|e| SweepError::io(format!("creating {}", tmp.display()), e))?;
    let props = Arc::new(WriterProperties::builder().build());
    let mut writer =
        SerializedFileWriter::new(file, Arc::new(schema), props).map_err(|e| err(path, e))?;
    let mut group = writer.next_row_group().map_err(|e| err(path, e))?;
    let mut c = 0;
    while let Some(mut column) = group.next_column().map_err(|e| err(path, e))? {
        let cells: Vec<&str> = rows.iter().map(|r| cell(r, c)).collect();
        let present: Vec<&str> = cells.iter().copied().filter(|s| !s.is_empty()).collect();
        let levels: Vec<i16> = cells.iter().map(|s| i16::from(!s.is_empty())).collect();
        // The kinds were chosen so that every present cell parses.
        let written = match column.untyped() {
            ColumnWriter::Int64ColumnWriter(w) => {
                let v: Vec<i64> = present.iter().map(|s| s.parse().unwrap_or(0)).collect();
                w.write_batch(&v, Some(&levels), None)
            }
            ColumnWriter::DoubleColumnWriter(w) => {
                let v: Vec<f64> = present
                    .iter()
                    .map(|s| s.parse().unwrap_or(f64::NAN))
                    .collect();
                w.write_batch(&v, Some(&levels), None)
            }
            ColumnWriter::ByteArrayColumnWriter(w) => {
                let v: Vec<ByteArray> = present.iter().map(|s| ByteArray::from(*s)).collect();
                w.write_batch(&v, Some(&levels), None)
            }
            _ => unreachable!("only INT64, DOUBLE and BYTE_ARRAY columns are declared"),
        };
        written.map_err(|e| err(path, e))?;
        column.close().map_err(|e| err(path, e))?;
        c += 1;
    }
    group.close().map_err(|e| err(path, e))?;
    writer.close().map_err(|e| err(path, e))?;
    std::fs::rename(&tmp, path)
        .map_err(|e| SweepError::io(format!("replacing {}", path.display()), e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;

    #[test]
    fn integers_numbers_text_and_empty_cells_read_back_typed() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(PARQUET_FILE);
        let columns: Vec<String> = ["run", "pheromones[0].evaporation", "group", "s_halve_time"]
            .map(String::from)
            .to_vec();
        let rows = [
            ["0", "2.5", "a,b", ""].map(String::from),
            ["1", "10", "c", "4.25"].map(String::from),
        ];
        let refs: Vec<&[String]> = rows.iter().map(|r| &r[..]).collect();
        write_parquet(&path, &columns, &refs).unwrap();
        let reader = SerializedFileReader::new(std::fs::File::open(&path).unwrap()).unwrap();
        let got: Vec<Vec<(String, Field)>> = reader
            .get_row_iter(None)
            .unwrap()
            .map(|row| {
                row.unwrap()
                    .get_column_iter()
                    .map(|(n, f)| (n.clone(), f.clone()))
                    .collect()
            })
            .collect();
        assert_eq!(got.len(), 2);
        assert_eq!(got[0][0], ("run".into(), Field::Long(0)));
        assert_eq!(
            got[0][1],
            ("pheromones[0].evaporation".into(), Field::Double(2.5))
        );
        assert_eq!(got[0][2], ("group".into(), Field::Str("a,b".into())));
        assert_eq!(got[0][3], ("s_halve_time".into(), Field::Null));
        assert_eq!(got[1][1].1, Field::Double(10.0));
        assert_eq!(got[1][3].1, Field::Double(4.25));
        assert!(!path.with_extension("parquet.tmp").exists());
    }

    #[test]
    fn a_column_is_as_wide_as_its_widest_cell() {
        assert_eq!(kind_of(["1", "", "-3"].into_iter()), Kind::Int);
        assert_eq!(kind_of(["1", "NaN"].into_iter()), Kind::Double);
        assert_eq!(kind_of(["1", "x", "2.0"].into_iter()), Kind::Text);
        assert_eq!(kind_of(["", ""].into_iter()), Kind::Int);
    }
}
