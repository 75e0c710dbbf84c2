MODULE Seam
  ! Fillet weld along the table edge. Tool and work object as in the cell.
  PERS tooldata torch:=[TRUE,[[125,0,216.50635],[0.965925826,0,0.258819045,0]],[2.5,[0,0,120],[1,0,0,0],0,0,0]];
  TASK PERS wobjdata table:=[FALSE,TRUE,"",[[1300,-600,300],[0.984807753,0,0,0.173648178]],[[0,0,0],[1,0,0,0]]];
  CONST jointtarget home:=[[0,90,-20,0,45,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p10:=[[0,0,0],[0,1,0,0],[-1,1,1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget p20:=[[100,0,0],[0,1,0,0],[-1,1,1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  CONST robtarget arc{2}:=[[[200,150,0],[0,1,0,0],[-1,1,1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]],
                           [[0,150,0],[0,1,0,0],[-1,1,1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]]];

  PROC main()
    MoveAbsJ home, v1000, fine, tool0;
    MoveJ p10, v1000, z50, torch\WObj:=table;
    MoveL p20, v200, fine, torch\WObj:=table;
    SetDO doArc, 1; ! arc on
    MoveL [[200,50,0],[0,1,0,0],[-1,1,1,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]], v20, z1, torch\WObj:=table;
    MoveC arc{1}, arc{2}, v20, z1, torch\WObj:=table;
    SetDO doArc, 0; ! arc off
    MoveAbsJ home, v1000, fine, tool0;
  ENDPROC
ENDMODULE
