use super::*;

fn read(text: &str) -> Result<StepFile, StepError> {
    StepFile::from_bytes(text.as_bytes().to_vec(), &ReadOptions::default())
}

const GOOD: &str = "ISO-10303-21;\nHEADER;\n/* c */FILE_DESCRIPTION(('d'),'2;1');\nFILE_NAME('f','t',('a'),('o'),'p','Tool X','');\nFILE_SCHEMA(('IFC4'));\nENDSEC;\nDATA;\n#1=IFCCARTESIANPOINT((0.,1.,2.));\n#2 = IFCDIRECTION ( (1.,0.,0.) ) ;\n#10=IFCLABEL('a;b''c/*');\nENDSEC;\nEND-ISO-10303-21;\n";

#[test]
fn reads_header_and_index() {
    let f = read(GOOD).unwrap();
    assert_eq!(f.header.schemas, vec!["IFC4"]);
    assert_eq!(f.header.originating_system, "Tool X");
    assert_eq!(f.len(), 3);
    let e = f.entity(2).unwrap().unwrap();
    assert_eq!(e.type_name, "IFCDIRECTION");
    let e = f.entity(10).unwrap().unwrap();
    assert_eq!(e.get(0).text().unwrap().0, "a;b'c/*");
    assert!(f.entity(3).is_none());
    assert_eq!(f.of_type("IFCDIRECTION").count(), 1);
}

#[test]
fn cr_only_line_ends() {
    let f = read(&GOOD.replace('\n', "\r")).unwrap();
    let r = f.record(2).unwrap();
    assert_eq!(f.line_col(r.start).0, 9);
}

#[test]
fn errors_name_lines() {
    let e = read("HEADER;").unwrap_err();
    assert_eq!(e.kind, StepErrorKind::NotStep);
    let e = read("ISO-10303-21;\nDATA;\nENDSEC;").unwrap_err();
    assert_eq!((e.kind, e.line), (StepErrorKind::MissingHeader, 2));
    let cut = &GOOD[..GOOD.find("#2").unwrap() + 12];
    let e = read(cut).unwrap_err();
    assert!(matches!(e.kind, StepErrorKind::Truncated { .. }), "{e}");
    assert_eq!(e.line, 9);
    let dup = GOOD.replace("#10=", "#1=");
    let e = read(&dup).unwrap_err();
    assert!(
        matches!(
            e.kind,
            StepErrorKind::DuplicateId {
                id: 1,
                first_line: 8,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(e.line, 10);
}

#[test]
fn sparse_ids_use_sorted_lookup() {
    let text = GOOD.replace("#10=", "#9000000000=");
    let f = read(&text).unwrap();
    assert!(f.entity(9_000_000_000).is_some());
    assert!(f.entity(10).is_none());
}

#[test]
fn size_limit() {
    let options = ReadOptions {
        max_bytes: 10,
        ..ReadOptions::default()
    };
    let e = StepFile::from_bytes(GOOD.as_bytes().to_vec(), &options).unwrap_err();
    assert!(matches!(e.kind, StepErrorKind::TooLarge { .. }));
}

/// A file of `n` entities with `middle` (entity statements) placed halfway, big enough
/// to be scanned in chunks.
fn big_file(n: usize, middle: &str) -> String {
    let mut text = String::from(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\nFILE_NAME('','',(''),(''),'','','');\nFILE_SCHEMA(('IFC4'));\nENDSEC;\nDATA;\n",
    );
    for i in 1..=n {
        if i == n / 2 {
            text.push_str(middle);
        }
        // Strings and comments with `;` everywhere a chunk might start.
        match i % 3 {
            0 => text.push_str(&format!("#{i}=IFCLABEL('x;{i};#9=IFCX((1.));');\n")),
            1 => text.push_str(&format!(
                "/* ;#{i}=( */#{i}= IfcCartesianPoint((0.,{i}.,2.));\n"
            )),
            _ => text.push_str(&format!("#{i}=IFCDIRECTION((1.,0.,0.));\n")),
        }
    }
    text.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    text
}

/// The file read in one pass (one thread) and in chunks (four threads).
fn read_both(text: &str) -> [Result<StepFile, StepError>; 2] {
    [1, 4].map(|threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| read(text))
    })
}

/// Each record as (id, type, start, parameters), and the type names.
type Index = (Vec<(u64, u32, usize, (usize, usize))>, Vec<String>);

fn index_of(f: &StepFile) -> Index {
    let records = f
        .records()
        .iter()
        .map(|r| (r.id, r.type_id, r.start, r.params))
        .collect();
    (records, f.type_names.clone())
}

#[test]
fn chunks_index_exactly_what_one_pass_does() {
    let long_string = format!("#999999=IFCLABEL('{}');\n", ";#1=A(1);".repeat(200_000));
    let long_comment = format!("/* {} */\n", ";#1=A(1);".repeat(200_000));
    let second_section = "ENDSEC;\nDATA;\n#888888=IFCLABEL('s');\n";
    // Four chunks, some starting inside the long string or comment (scanned again from
    // where the chunk before ended); a second section falls back to one pass.
    for (middle, chunks) in [
        ("", 4),
        (long_string.as_str(), 4),
        (long_comment.as_str(), 4),
        (second_section, 1),
    ] {
        let text = big_file(100_000, middle);
        assert!(text.len() > 4 * MIN_CHUNK_BYTES, "{}", text.len());
        let [one, chunked] = read_both(&text);
        let (one, chunked) = (one.expect("reads"), chunked.expect("reads"));
        assert_eq!(index_of(&one), index_of(&chunked));
        assert_eq!((one.scan_chunks(), chunked.scan_chunks()), (1, chunks));
        assert!(one.len() >= 100_000);
        assert_eq!(
            chunked.entity(2).unwrap().unwrap().type_name,
            "IFCDIRECTION"
        );
    }
}

#[test]
fn chunks_report_an_error_where_one_pass_does() {
    for middle in [
        "#5=IFCLABEL('unclosed);\n",
        "#5 IFCLABEL('a');\n",
        "#5=IFCLABEL('a';\n",
        "#40000=IFCLABEL('taken');\n",
    ] {
        let text = big_file(100_000, middle);
        let [one, chunked] = read_both(&text);
        let (one, chunked) = (one.expect_err("fails"), chunked.expect_err("fails"));
        assert_eq!(
            (one.to_string(), one.line, one.column, one.entity),
            (
                chunked.to_string(),
                chunked.line,
                chunked.column,
                chunked.entity
            )
        );
    }
    let truncated = big_file(100_000, "");
    let truncated = &truncated[..truncated.len() * 3 / 4];
    let [one, chunked] = read_both(truncated);
    let (one, chunked) = (one.expect_err("fails"), chunked.expect_err("fails"));
    assert_eq!(one.to_string(), chunked.to_string());
}
