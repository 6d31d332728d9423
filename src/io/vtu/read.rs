//! Scanning a `.vtu` file: the XML structure, its data arrays, and their decoded values.

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

use super::data::{self, Layout, Scalar};
use crate::io::ParseError;

/// The part of the piece an array belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Section {
    Points,
    Cells,
    CellData,
    Other,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    Binary,
    Appended(usize),
}

/// One `DataArray`.
#[derive(Clone, Debug)]
pub struct Array<'a> {
    pub section: Section,
    pub name: String,
    pub ty: Scalar,
    pub components: usize,
    format: Format,
    /// The element's text (ASCII numbers or base64).
    text: &'a [u8],
    /// Byte offset of the element, for errors.
    at: usize,
}

/// The `AppendedData` after the XML: base64 text or raw bytes, after the `_` marker.
struct Appended<'a> {
    raw: bool,
    data: &'a [u8],
    /// Byte offset of `data` in the file.
    at: usize,
}

/// What a `.vtu` file holds.
pub struct VtuFile<'a> {
    bytes: &'a [u8],
    layout: Layout,
    pub points: usize,
    pub cells: usize,
    pub arrays: Vec<Array<'a>>,
    appended: Option<Appended<'a>>,
}

/// 1-based line of a byte offset.
fn line_of(bytes: &[u8], at: usize) -> usize {
    1 + bytes[..at.min(bytes.len())].iter().filter(|&&b| b == b'\n').count()
}

/// An error at a byte offset of the XML, reported by its line.
pub fn error_at(bytes: &[u8], at: usize, message: impl Into<String>) -> ParseError {
    ParseError::at_line(line_of(bytes, at), message)
}

fn attribute(e: &BytesStart, name: &str) -> Option<String> {
    let a = e.try_get_attribute(name).ok()??;
    Some(String::from_utf8_lossy(&a.value).into_owned())
}

/// Split off the `AppendedData` (raw bytes would confuse an XML parser).
fn split_appended(bytes: &[u8]) -> Result<(&[u8], Option<Appended<'_>>), ParseError> {
    let tag = b"<AppendedData";
    let Some(start) = bytes.windows(tag.len()).position(|w| w == tag) else {
        return Ok((bytes, None));
    };
    let tag_end = bytes[start..].iter().position(|&b| b == b'>').map(|p| start + p);
    let Some(tag_end) = tag_end else {
        return Err(error_at(bytes, start, "unterminated <AppendedData> tag"));
    };
    let head = String::from_utf8_lossy(&bytes[start..tag_end]);
    let raw = head.contains("\"raw\"") || head.contains("'raw'");
    let underscore = bytes[tag_end..].iter().position(|&b| b == b'_').map(|p| tag_end + p + 1);
    let Some(at) = underscore else {
        return Err(error_at(bytes, tag_end, "AppendedData without its '_' marker"));
    };
    let mut data = &bytes[at..];
    if !raw {
        let close = b"</AppendedData>";
        if let Some(end) = data.windows(close.len()).position(|w| w == close) {
            data = &data[..end];
        }
    }
    Ok((&bytes[..start], Some(Appended { raw, data, at })))
}

/// Parse the XML structure of a `.vtu` file.
pub fn scan(bytes: &[u8]) -> Result<VtuFile<'_>, ParseError> {
    let (xml, appended) = split_appended(bytes)?;
    let mut reader = Reader::from_reader(xml);
    let mut file = VtuFile {
        bytes,
        layout: Layout { header: Scalar::U32, swap: false, compressed: false },
        points: 0,
        cells: 0,
        arrays: Vec::new(),
        appended,
    };
    let mut section = Section::Other;
    let mut seen_root = false;
    let mut pieces = 0;
    loop {
        let at = reader.buffer_position() as usize;
        let event = reader
            .read_event()
            .map_err(|e| error_at(bytes, reader.error_position() as usize, format!("bad XML: {e}")))?;
        match event {
            Event::Empty(e) if e.local_name().as_ref() == b"DataArray" => {
                file.arrays.push(data_array(bytes, &e, at, section)?);
            }
            Event::Start(e) if e.local_name().as_ref() == b"DataArray" => {
                let mut array = data_array(bytes, &e, at, section)?;
                let span = reader
                    .read_to_end(e.to_end().name())
                    .map_err(|err| error_at(bytes, at, format!("unterminated DataArray: {err}")))?;
                array.text = xml.get(span.start as usize..span.end as usize).unwrap_or_default();
                file.arrays.push(array);
            }
            Event::Start(e) | Event::Empty(e) => match e.local_name().as_ref() {
                b"VTKFile" => {
                    seen_root = true;
                    read_root(bytes, &e, at, &mut file)?;
                }
                b"Piece" => {
                    pieces += 1;
                    if pieces > 1 {
                        return Err(error_at(
                            bytes,
                            at,
                            "several <Piece>s: only single-piece files are read",
                        ));
                    }
                    file.points = count_attribute(bytes, &e, at, "NumberOfPoints")?;
                    file.cells = count_attribute(bytes, &e, at, "NumberOfCells")?;
                }
                b"Points" => section = Section::Points,
                b"Cells" => section = Section::Cells,
                b"CellData" => section = Section::CellData,
                b"PointData" | b"FieldData" => section = Section::Other,
                _ => {}
            },
            Event::End(e) if matches!(e.local_name().as_ref(), b"Points" | b"Cells" | b"CellData") => {
                section = Section::Other;
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if !seen_root {
        return Err(ParseError::file("no <VTKFile> element: not a VTK XML file"));
    }
    if pieces == 0 {
        return Err(ParseError::file("no <Piece> element"));
    }
    Ok(file)
}

fn read_root(bytes: &[u8], e: &BytesStart, at: usize, file: &mut VtuFile) -> Result<(), ParseError> {
    if let Some(t) = attribute(e, "type") {
        if t != "UnstructuredGrid" {
            return Err(error_at(bytes, at, format!("VTK file of type '{t}', expected UnstructuredGrid")));
        }
    }
    file.layout.swap = attribute(e, "byte_order").is_some_and(|b| b == "BigEndian");
    file.layout.header = match attribute(e, "header_type").as_deref() {
        None | Some("UInt32") => Scalar::U32,
        Some("UInt64") => Scalar::U64,
        Some(h) => return Err(error_at(bytes, at, format!("unsupported header_type '{h}'"))),
    };
    file.layout.compressed = match attribute(e, "compressor").as_deref() {
        None | Some("") => false,
        Some("vtkZLibDataCompressor") => true,
        Some(c) => {
            return Err(error_at(
                bytes,
                at,
                format!("unsupported compressor '{c}' (only vtkZLibDataCompressor)"),
            ))
        }
    };
    Ok(())
}

fn count_attribute(bytes: &[u8], e: &BytesStart, at: usize, name: &str) -> Result<usize, ParseError> {
    let value = attribute(e, name).ok_or_else(|| error_at(bytes, at, format!("<Piece> without {name}")))?;
    value.trim().parse().map_err(|_| error_at(bytes, at, format!("{name}=\"{value}\" is not a count")))
}

fn data_array<'a>(
    bytes: &[u8],
    e: &BytesStart,
    at: usize,
    section: Section,
) -> Result<Array<'a>, ParseError> {
    let ty_name = attribute(e, "type").unwrap_or_default();
    let ty = Scalar::parse(&ty_name)
        .ok_or_else(|| error_at(bytes, at, format!("DataArray of unsupported type '{ty_name}'")))?;
    let components = match attribute(e, "NumberOfComponents") {
        None => 1,
        Some(c) => {
            c.trim().parse().map_err(|_| error_at(bytes, at, format!("bad NumberOfComponents '{c}'")))?
        }
    };
    let format = match attribute(e, "format").as_deref() {
        Some("ascii") => Format::Ascii,
        Some("binary") => Format::Binary,
        Some("appended") => {
            let offset = attribute(e, "offset").unwrap_or_default();
            let offset =
                offset.trim().parse().map_err(|_| error_at(bytes, at, format!("bad offset '{offset}'")))?;
            Format::Appended(offset)
        }
        other => return Err(error_at(bytes, at, format!("DataArray of unknown format {other:?}"))),
    };
    let name = attribute(e, "Name").unwrap_or_default();
    Ok(Array { section, name, ty, components, format, text: &[], at })
}

/// Raw values of an array: its bytes (binary) or its text (ASCII).
enum Raw<'t> {
    Binary(Vec<u8>),
    Text(&'t [u8]),
}

impl<'a> VtuFile<'a> {
    pub fn error(&self, array: &Array, message: impl Into<String>) -> ParseError {
        error_at(self.bytes, array.at, format!("DataArray '{}': {}", array.name, message.into()))
    }

    pub fn find(&self, section: Section, name: Option<&str>) -> Option<&Array<'a>> {
        self.arrays.iter().find(|a| a.section == section && name.is_none_or(|n| a.name == n))
    }

    fn raw<'t>(&self, array: &Array<'t>) -> Result<Raw<'t>, ParseError> {
        let fail = |m: String| self.error(array, m);
        match array.format {
            Format::Ascii => Ok(Raw::Text(array.text)),
            Format::Binary => {
                let decoded = data::base64(array.text).map_err(fail)?;
                Ok(Raw::Binary(data::block(&decoded, self.layout).map_err(fail)?.0))
            }
            Format::Appended(offset) => {
                let app = self
                    .appended
                    .as_ref()
                    .ok_or_else(|| fail("appended array but no <AppendedData>".into()))?;
                let rest = app
                    .data
                    .get(offset..)
                    .ok_or_else(|| fail(format!("offset {offset} past the appended data")))?;
                let bytes = if app.raw {
                    rest.to_vec()
                } else {
                    data::base64(self.base64_run(rest, offset)).map_err(fail)?
                };
                let (data, _) = data::block(&bytes, self.layout).map_err(|m| {
                    ParseError::at_byte((app.at + offset) as u64, format!("DataArray '{}': {m}", array.name))
                })?;
                Ok(Raw::Binary(data))
            }
        }
    }

    /// The base64 text of the appended array at `offset`: up to the next array's offset.
    fn base64_run<'b>(&self, rest: &'b [u8], offset: usize) -> &'b [u8] {
        let next = self
            .arrays
            .iter()
            .filter_map(|a| match a.format {
                Format::Appended(o) if o > offset => Some(o - offset),
                _ => None,
            })
            .min();
        next.map_or(rest, |n| &rest[..n.min(rest.len())])
    }

    /// The values of an integer array.
    pub fn ints(&self, array: &Array) -> Result<Vec<i64>, ParseError> {
        match self.raw(array)? {
            Raw::Text(t) => data::ascii(t),
            Raw::Binary(b) => data::ints(&b, array.ty, self.layout.swap),
        }
        .map_err(|m| self.error(array, m))
    }

    /// The values of a numeric array as floats.
    pub fn floats(&self, array: &Array) -> Result<Vec<f64>, ParseError> {
        match self.raw(array)? {
            Raw::Text(t) => data::ascii(t).map_err(|m| self.error(array, m)),
            Raw::Binary(b) => Ok(data::floats(&b, array.ty, self.layout.swap)),
        }
    }
}
