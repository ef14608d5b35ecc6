# A 10 m simply supported beam: gravity (static), loadConst, eigen, then a transient under a
# Path load given as a Tcl list; Newmark; text recorder. Runs in OpenSees's Tcl interpreter
# and with vtsi: python -m vtsi beam.tcl [outdir]
set outdir [expr {$argc > 0 ? [lindex $argv 0] : "."}]
wipe
model basic -ndm 2 -ndf 3
set nel 8
set L 10.0
for {set i 0} {$i <= $nel} {incr i} {
    node [expr {$i + 1}] [expr {$i * $L / $nel}] 0.0
}
fix 1 1 1 0
fix [expr {$nel + 1}] 0 1 0
geomTransf Linear 1
for {set i 1} {$i <= $nel} {incr i} {
    element elasticBeamColumn $i $i [expr {$i + 1}] 0.8 3.0e10 0.05 1 -mass 2000.0 -cMass
}
mass 5 500.0 500.0 0.0

timeSeries Linear 1
pattern Plain 1 1 {
    for {set i 2} {$i <= $nel} {incr i} {
        load $i 0.0 [expr {-2000.0 * 9.81 * $L / $nel}] 0.0
    }
}
constraints Plain
numberer RCM
system BandSPD
test NormDispIncr 1.0e-10 6
algorithm Linear
integrator LoadControl 0.25
analysis Static
analyze 4
puts "static midspan [nodeDisp 5 2]"
loadConst -time 0.0

set lambda [eigen 3]
puts "eigen $lambda"
set w1 [expr {sqrt([lindex $lambda 0])}]
rayleigh 0.0 [expr {0.04 / $w1}] 0.0 0.0

set values {}
for {set k 0} {$k <= 50} {incr k} {
    lappend values [expr {sin(3.14159265358979 * $k / 50.0)}]
}
timeSeries Path 2 -dt 0.005 -values $values -factor 1.0e5
pattern Plain 2 2 -fact 1.5 {
    load 4 0.0 -1.0 0.0
}
pattern Plain 3 "Path -time {0.0 0.1 0.2} -values {0.0 2.0e4 0.0}" {
    load 6 1.0 -1.0 0.0
}
recorder Node -file [file join $outdir tcl_disp.out] -time -node 3 5 -dof 2 disp
wipeAnalysis
constraints Transformation
numberer RCM
system BandGeneral
algorithm Newton
integrator Newmark 0.5 0.25
analysis Transient
set ok [analyze 60 0.005]
puts "analyze $ok t [getTime] disp [nodeDisp 5 2] force [eleForce 4 2]"
wipe
