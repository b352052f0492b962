//! Writes a layout as an IFC file (ISO 10303-21 text) and its truth sidecar.
//!
//! Options vary what real authoring tools vary: schema, length unit, product
//! classes, grouping of members under a wall, mapped-item pieces, and what member
//! placements are relative to. Output is deterministic: GlobalIds come from a
//! seeded hash of stable keys, timestamps are fixed, caches are BTreeMaps.

mod ctx;
mod members;
mod options;
mod spatial;
mod truth_rows;

pub use options::{Grouping, PlacementBase, ProductClasses, Schema, WriteOptions, WrittenModel};

use crate::step::text::{Real, Ref, RefList, StepWriter, string};
use crate::synth::error::SynthError;
use crate::synth::layout::Layout;
use crate::synth::units::LengthUnit;
use ctx::Ctx;
use spatial::write_building;
use std::collections::BTreeMap;
use truth_rows::build_truth;

/// Fixed time stamp (2024-01-01T00:00:00Z) so files are byte-identical across runs.
const TIMESTAMP: u64 = 1_704_067_200;
const MATERIAL: &str = "Spruce-Pine-Fir No.2";

/// Write `layout` with `opts`.
pub fn write_ifc(layout: &Layout, opts: &WriteOptions) -> Result<WrittenModel, SynthError> {
    let base = opts.placement_base()?;
    if layout.piece_count() == 0 {
        return Err(SynthError::Options {
            what: "the layout has no pieces".into(),
            hint: "frame at least one wall".into(),
        });
    }
    let schema = opts.schema;
    let mut ctx = Ctx {
        w: StepWriter::new(512 * layout.piece_count() + 8192),
        opts,
        scale: 1.0 / opts.unit.metres_per_unit(),
        key_prefix: layout.name.clone(),
        owner: Ref(0),
        body: Ref(0),
        origin: Ref(0),
        origin2d: Ref(0),
        identity: Ref(0),
        dirs: BTreeMap::new(),
        profiles: BTreeMap::new(),
        maps: BTreeMap::new(),
    };
    let w = &mut ctx.w;
    let person = w.add("IFCPERSON", "$,'synth','framewright',$,$,$,$,$");
    let org = w.add("IFCORGANIZATION", "$,'framewright',$,$,$");
    let pando = w.add("IFCPERSONANDORGANIZATION", format_args!("{person},{org},$"));
    let app = w.add(
        "IFCAPPLICATION",
        format_args!("{org},'1.0','framewright synth','framewright-synth'"),
    );
    ctx.owner = w.add(
        "IFCOWNERHISTORY",
        format_args!("{pando},{app},$,.ADDED.,{TIMESTAMP},$,$,{TIMESTAMP}"),
    );
    ctx.origin = ctx.w.add("IFCCARTESIANPOINT", "(0.,0.,0.)");
    ctx.origin2d = ctx.w.add("IFCCARTESIANPOINT", "(0.,0.)");
    ctx.identity = ctx
        .w
        .add("IFCAXIS2PLACEMENT3D", format_args!("{},$,$", ctx.origin));
    let north = ctx.w.add("IFCDIRECTION", "(0.,1.)");
    let context = ctx.w.add(
        "IFCGEOMETRICREPRESENTATIONCONTEXT",
        format_args!(
            "$,'Model',3,{},{},{north}",
            Real(1e-5 * ctx.scale),
            ctx.identity
        ),
    );
    ctx.body = ctx.w.add(
        "IFCGEOMETRICREPRESENTATIONSUBCONTEXT",
        format_args!("'Body','Model',*,*,*,*,{context},$,.MODEL_VIEW.,$"),
    );
    let units = write_units(&mut ctx.w, opts.unit);
    let project = format!(
        "{},{},{},$,$,$,({context}),{units}",
        ctx.owner_args("project"),
        string(&layout.name),
        string(&layout.description)
    );
    let project = ctx.w.add("IFCPROJECT", project);
    let site_lp = ctx.local_placement(None, ctx.identity);
    let site_args = format!(
        "{},'Site',$,$,{site_lp},$,$,.ELEMENT.,$,$,$,$,$",
        ctx.owner_args("site")
    );
    let site = ctx.w.add("IFCSITE", site_args);
    let material = match schema {
        Schema::Ifc2x3 => ctx.w.add("IFCMATERIAL", string(MATERIAL)),
        _ => ctx
            .w
            .add("IFCMATERIAL", format_args!("{},$,'Wood'", string(MATERIAL))),
    };

    let mut truth_members = Vec::with_capacity(layout.piece_count());
    let mut truth_walls = Vec::new();
    let mut buildings = Vec::new();
    for b in &layout.buildings {
        let b_ref = write_building(
            &mut ctx,
            b,
            site_lp,
            base,
            material,
            &mut truth_members,
            &mut truth_walls,
        )?;
        buildings.push(b_ref);
    }
    let agg = ctx.owner_args("rel:project-site");
    ctx.w.add(
        "IFCRELAGGREGATES",
        format_args!("{agg},$,$,{project},({site})"),
    );
    let agg = ctx.owner_args("rel:site-buildings");
    ctx.w.add(
        "IFCRELAGGREGATES",
        format_args!("{agg},$,$,{site},{}", RefList(&buildings)),
    );

    let header = format!(
        "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(({}),'2;1');\nFILE_NAME({},'2024-01-01T00:00:00',('framewright'),('framewright'),'framewright synth','framewright synth','');\nFILE_SCHEMA(('{}'));\nENDSEC;\nDATA;\n",
        string(match schema {
            Schema::Ifc2x3 => "ViewDefinition [CoordinationView_V2.0]",
            _ => "ViewDefinition [DesignTransferView]",
        }),
        string(&opts.file_name),
        schema.header_name()
    );
    let body = ctx.w.into_text();
    let mut ifc = String::with_capacity(header.len() + body.len() + 32);
    ifc.push_str(&header);
    ifc.push_str(&body);
    ifc.push_str("ENDSEC;\nEND-ISO-10303-21;\n");

    let truth = build_truth(layout, opts, base, truth_members, truth_walls);
    Ok(WrittenModel { ifc, truth })
}

fn write_units(w: &mut StepWriter, unit: LengthUnit) -> Ref {
    let length = match unit {
        LengthUnit::Metre => w.add("IFCSIUNIT", "*,.LENGTHUNIT.,$,.METRE."),
        LengthUnit::Millimetre => w.add("IFCSIUNIT", "*,.LENGTHUNIT.,.MILLI.,.METRE."),
        LengthUnit::Foot | LengthUnit::Inch => {
            let dims = w.add("IFCDIMENSIONALEXPONENTS", "1,0,0,0,0,0,0");
            let metre = w.add("IFCSIUNIT", "*,.LENGTHUNIT.,$,.METRE.");
            let factor = w.add(
                "IFCMEASUREWITHUNIT",
                format_args!("IFCLENGTHMEASURE({}),{metre}", Real(unit.metres_per_unit())),
            );
            w.add(
                "IFCCONVERSIONBASEDUNIT",
                format_args!("{dims},.LENGTHUNIT.,{},{factor}", string(unit.ifc_name())),
            )
        }
    };
    let area = w.add("IFCSIUNIT", "*,.AREAUNIT.,$,.SQUARE_METRE.");
    let volume = w.add("IFCSIUNIT", "*,.VOLUMEUNIT.,$,.CUBIC_METRE.");
    let angle = w.add("IFCSIUNIT", "*,.PLANEANGLEUNIT.,$,.RADIAN.");
    w.add(
        "IFCUNITASSIGNMENT",
        format_args!("({length},{area},{volume},{angle})"),
    )
}
