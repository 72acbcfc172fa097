mod common;

use umbra_gl::glow::{self, HasContext};

#[test]
fn explore_quad_tessellation() {
    let ctx = common::context();
    let gl = ctx.gl();
    let vs = "#version 450 core\nvoid main(){ gl_Position = vec4(float(gl_VertexID)); }\n";
    let tcs = "#version 450 core\nlayout(vertices = 4) out;\nvoid main(){ gl_out[gl_InvocationID].gl_Position = vec4(0.0);\n if (gl_InvocationID == 0) { gl_TessLevelOuter[0]=1.0; gl_TessLevelOuter[1]=5.0; gl_TessLevelOuter[2]=1.0; gl_TessLevelOuter[3]=5.0; gl_TessLevelInner[0]=5.0; gl_TessLevelInner[1]=1.0; } }\n";
    let tes = "#version 450 core\nlayout(quads, fractional_odd_spacing, ccw) in;\nout vec2 tc;\nvoid main(){ tc = gl_TessCoord.xy; gl_Position = vec4(tc, 0.0, 1.0); }\n";
    unsafe {
        let program = gl.create_program().unwrap();
        for (stage, src) in [(glow::VERTEX_SHADER, vs), (glow::TESS_CONTROL_SHADER, tcs), (glow::TESS_EVALUATION_SHADER, tes)] {
            let s = gl.create_shader(stage).unwrap();
            gl.shader_source(s, src);
            gl.compile_shader(s);
            assert!(gl.get_shader_compile_status(s), "{}", gl.get_shader_info_log(s));
            gl.attach_shader(program, s);
        }
        gl.transform_feedback_varyings(program, &["tc"], glow::INTERLEAVED_ATTRIBS);
        gl.link_program(program);
        assert!(gl.get_program_link_status(program), "{}", gl.get_program_info_log(program));
        let buf = gl.create_buffer().unwrap();
        gl.bind_buffer(glow::TRANSFORM_FEEDBACK_BUFFER, Some(buf));
        gl.buffer_data_size(glow::TRANSFORM_FEEDBACK_BUFFER, 4096, glow::STATIC_READ);
        gl.bind_buffer_base(glow::TRANSFORM_FEEDBACK_BUFFER, 0, Some(buf));
        let fb = gl.create_framebuffer().unwrap();
        let rb = gl.create_renderbuffer().unwrap();
        gl.bind_renderbuffer(glow::RENDERBUFFER, Some(rb));
        gl.renderbuffer_storage(glow::RENDERBUFFER, glow::RGBA8, 4, 4);
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fb));
        gl.framebuffer_renderbuffer(glow::FRAMEBUFFER, glow::COLOR_ATTACHMENT0, glow::RENDERBUFFER, Some(rb));
        let vao = gl.create_vertex_array().unwrap();
        gl.bind_vertex_array(Some(vao));
        gl.use_program(Some(program));
        gl.patch_parameter_i32(glow::PATCH_VERTICES, 3);
        gl.enable(glow::RASTERIZER_DISCARD);
        let q = gl.create_query().unwrap();
        gl.begin_query(glow::TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN, q);
        gl.begin_transform_feedback(glow::TRIANGLES);
        gl.draw_arrays(glow::PATCHES, 0, 3);
        gl.end_transform_feedback();
        gl.end_query(glow::TRANSFORM_FEEDBACK_PRIMITIVES_WRITTEN);
        gl.disable(glow::RASTERIZER_DISCARD);
        let n = gl.get_query_parameter_u32(q, glow::QUERY_RESULT);
        println!("errors {:?} err {}", ctx.take_gl_errors(), gl.get_error());
        let n = if n == 0 { 40 } else { n };
        let mut bytes = vec![0u8; n as usize * 3 * 8];
        gl.get_buffer_sub_data(glow::TRANSFORM_FEEDBACK_BUFFER, 0, &mut bytes);
        let f: Vec<f32> = bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        println!("{n} triangles");
        for t in f.chunks_exact(6) {
            println!("({:?},{:?}) ({:?},{:?}) ({:?},{:?})", t[0], t[1], t[2], t[3], t[4], t[5]);
        }
    }
}
